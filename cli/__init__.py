"""The `designer` command: a thin typer layer over the `designer` library."""
