"""Entry point of ``python -m pdverify``."""
import sys

from .cli import main

sys.exit(main())
