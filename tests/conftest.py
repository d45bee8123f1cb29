"""Tests run against the installed distribution (CI installs it non-editable), never the checkout."""

import os
import sys

_root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:] = [p for p in sys.path if os.path.abspath(p or os.curdir) != _root]
# Subprocesses that start the CLI with `python -I -c ...` for the same reason: isolated mode keeps the
# current directory (often the checkout) off sys.path.
