"""flexjoint designer: from print settings of TPU flexible joints to stiffness, damping and FMUs.

The library computes and returns plain data; the `designer` command (package `designer_cli`) is a
thin layer that parses, calls and prints.
"""

__version__ = "0.1.0"
