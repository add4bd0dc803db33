"""What the rotation commands write: the ECSV of the one output schema and the plot of what a paper reports.

The ECSV is the API's result table itself (``docs/conventions.md``, "Output tables"): ``time`` stays
an astropy Time column (TDB), every other column keeps its name and unit, and ``meta`` names the
epoch, frame, model and version, plus what the command adds. The plot shows, against calendar dates
(TDB), the periods (P_ψ, P_φ, sidereal), the spin pole (λ, β, ecliptic J2000), the obliquity when the
run has an orbit, and the mode, with the closest approach of each perturber the run sampled marked.
"""

from __future__ import annotations

#: Colours of the modes on the plot's mode strip.
MODE_COLOURS = {"SAM": "C0", "LAM": "C1", "separatrix": "C3", "permanent rotation": "C2"}


def ecsv_table(qtable, meta):
    """A plain astropy Table of the result table ``qtable`` (same columns and units) with ``meta`` added."""
    from astropy.table import Table

    table = Table(qtable, copy=True)
    table.meta.update(meta)
    return table


def _dates(times):
    """Matplotlib date numbers of astropy Times (TDB calendar dates; the axis says TDB)."""
    import matplotlib.dates as mdates

    return mdates.date2num(times.tdb.datetime64)


def plot_rotation(table, path, title, file_format="png", encounters=None):
    """Plot a result table of the output schema into ``path``.

    Panels: periods (h; P_ψ, P_φ and the sidereal period, P_ψ left out where infinite), the pole
    (λ, β in deg), the obliquity (deg, when the table has it), and a strip coloured by mode. Each
    closest approach in ``encounters`` ({name: {"time": ISO TDB, "distance_au": d}}) is a dashed line.
    """
    import matplotlib.dates as mdates
    import numpy as np
    from astropy.time import Time
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    has_periods = "P_psi" in table.colnames
    has_obliquity = "obliquity" in table.colnames
    panels = ["periods"] * has_periods + ["pole"] + ["obliquity"] * has_obliquity + ["mode"] * has_periods
    ratios = [3 if p != "mode" else 0.6 for p in panels]
    figure = Figure(figsize=(8, 1.2 + 1.9 * len(panels)), layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots(len(panels), 1, sharex=True, gridspec_kw={"height_ratios": ratios}, squeeze=False)[:, 0]
    dates = _dates(table["time"])
    by_name = dict(zip(panels, axes))
    if has_periods:
        ax = by_name["periods"]
        for name, label in (("P_psi", "P_ψ"), ("P_phi", "P_φ"), ("sidereal_period", "sidereal")):
            if name in table.colnames:
                values = _values(table[name], "h")
                if np.any(np.isfinite(values)):
                    ax.plot(dates, np.where(np.isfinite(values), values, np.nan), label=label)
        ax.set_ylabel("period [h]")
        ax.legend(loc="best", fontsize="small")
    ax = by_name["pole"]
    ax.plot(dates, _values(table["pole_lon"], "deg"), label="λ (ecliptic J2000)")
    ax.plot(dates, _values(table["pole_lat"], "deg"), label="β")
    ax.set_ylabel("pole [deg]")
    ax.legend(loc="best", fontsize="small")
    if has_obliquity:
        by_name["obliquity"].plot(dates, _values(table["obliquity"], "deg"), color="C4")
        by_name["obliquity"].set_ylabel("obliquity [deg]")
    if has_periods:
        ax = by_name["mode"]
        modes = np.asarray(table["mode"]).astype(str)
        edges = np.concatenate([dates[:1], 0.5 * (dates[1:] + dates[:-1]), dates[-1:]]) if len(dates) > 1 else \
            np.array([dates[0] - 0.5, dates[0] + 0.5])
        for mode in sorted(set(modes)):
            where = modes == mode
            for i in np.flatnonzero(where):
                ax.axvspan(edges[i], edges[i + 1], color=MODE_COLOURS.get(mode, "0.5"), lw=0)
            ax.plot([], [], color=MODE_COLOURS.get(mode, "0.5"), lw=6, label=mode)
        ax.set_yticks([])
        ax.set_ylabel("mode")
        ax.legend(loc="center left", bbox_to_anchor=(1.0, 0.5), fontsize="small", frameon=False)
    for name, approach in (encounters or {}).items():
        when = _dates(Time(approach["time"], scale="tdb"))
        if dates[0] <= when <= dates[-1]:
            for ax in axes:
                ax.axvline(when, color="0.3", ls="--", lw=0.8)
            axes[0].annotate(f"{name} {approach['distance_au']:.3g} au", (when, 1.0), xycoords=("data", "axes fraction"),
                             xytext=(3, -12), textcoords="offset points", fontsize="small")
    locator = mdates.AutoDateLocator()
    axes[-1].xaxis.set_major_locator(locator)
    axes[-1].xaxis.set_major_formatter(mdates.ConciseDateFormatter(locator))
    axes[-1].set_xlabel("date (TDB)")
    axes[0].set_title(title)
    figure.savefig(path, format=file_format, dpi=100)


def _values(column, unit):
    import numpy as np

    return np.asarray(column.to_value(unit) if hasattr(column, "to_value") else column, dtype=float)
