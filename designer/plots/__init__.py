"""Figures of the design space, the data and the surrogate: matplotlib 2D, pyvista 3D, all headless."""
