"""Figures of the design space, the data and the surrogate: matplotlib 2D, pyvista 3D, all headless.

Every `plot_*` function draws into the empty `matplotlib.figure.Figure` given as `fig=` or into a
new one with its own Agg canvas, and returns it; `common.save_figure(fig, path)` writes it. The 3D
views compute a `space.SpaceView`, `space.render(view)` draws it in its own off-screen pyvista
plotter, `space.save_screenshot` and `html3d.write_scene` write it; `profile` builds the prediction
profiler page. Nothing here switches matplotlib's backend, imports pyplot or edits the environment.
"""
