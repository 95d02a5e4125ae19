"""Analytic and manufactured references; never imports pdverify."""
