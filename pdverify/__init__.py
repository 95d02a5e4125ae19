"""pdverify: verification suite for peridynamic boundary corrections."""

__version__ = "0.1.0"
