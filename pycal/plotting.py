"""The one place that sets up matplotlib for pycal: no display, no global figure state.

Figures are made with new_figure() (matplotlib.figure.Figure, not pyplot: nothing to
close, safe in threads) and written with save_png() (atomic, pycal.files). Code that
still needs pyplot imports it from here: pycal.plotting.pyplot().
"""
import matplotlib

matplotlib.use("Agg")   # headless: rig folders, CI and clusters have no display


def new_figure(nrows=1, ncols=1, figsize=(6.4, 4.4)):
    """(figure, axes) of a new Figure; axes as matplotlib's subplots() returns them."""
    from matplotlib.figure import Figure
    fig = Figure(figsize=figsize)
    return fig, fig.subplots(nrows, ncols)


def save_png(fig, path, dpi=110):
    """Write the figure as PNG atomically. Returns path."""
    from .files import atomic_path
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi)
    return path


def pyplot():
    """matplotlib.pyplot with the Agg backend (for code that needs pyplot's state)."""
    import matplotlib.pyplot as plt
    return plt
