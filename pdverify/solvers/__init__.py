"""Solvers: static (direct, with constraints); later explicit dynamics and contact."""
