"""Exporters of a Joint: FMU (FMI 2/3), Modelica package, MJCF and URDF snippets."""
