"""Solvers: static (direct, with constraints), explicit dynamics, modal; later contact."""
