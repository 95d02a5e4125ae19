"""A plugin that ends the process as it is imported (pdverify must list it as broken and
go on)."""
import sys

sys.exit(3)
