"""Analytic and manufactured references; never imports pdverify."""
from .engine import solution  # noqa: F401
