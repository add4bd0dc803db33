"""What the rotation commands write: the ECSV of the one output schema and the plot of what a paper reports.

The ECSV is the API's result table itself (``docs/conventions.md``, "Output tables"): ``time`` stays
an astropy Time column (TDB), every other column keeps its name and unit, and ``meta`` names the
epoch, frame, model and version, plus what the command adds. The plot shows, against calendar dates
(TDB), what a paper would report of the run, with the closest approach of each perturber the run sampled
marked. For a tumbler (any row SAM or LAM): the periods (P_ψ, P_φ, sidereal), the spin pole (λ, β,
ecliptic J2000), the obliquity when the run has an orbit, and the rotation class. For a principal-axis
rotator (every row PA, ``docs/conventions.md``, "Wobble and rotation class") those are constant to the eye,
so it shows what changed: the pole's drift as an offset from its start (arcsec, east and north on the
sky of the ecliptic), the obliquity's change, the sidereal period's residual from its start and the
wobble amplitude.
"""

from __future__ import annotations

#: Colours of the rotation classes (or, in a table without them, the modes) on the plot's strip.
MODE_COLOURS = {"SAM": "C0", "LAM": "C1", "separatrix": "C3", "permanent rotation": "C2", "PA": "C2"}
ARCSEC_PER_DEG = 3600.0


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

    A principal-axis rotator (``rotation_class`` "PA" in every row) gets :func:`_principal_axis_panels`; any
    other table the periods (h; P_ψ, P_φ where not masked or infinite, and the sidereal period), the pole
    (λ, β in deg), the obliquity (deg, when the table has it) and a strip coloured by rotation class (or
    mode). Each approach in ``encounters`` ({name: {"time": ISO TDB, "distance_au": d}} or {name: [such
    approaches]}) is a dashed line labelled with the body and the distance.
    """
    import matplotlib.dates as mdates
    import numpy as np
    from astropy.time import Time
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    principal = "rotation_class" in table.colnames and bool(np.all(np.asarray(table["rotation_class"]) == "PA"))
    has_obliquity = "obliquity" in table.colnames
    if principal:
        panels = ["pole drift"] + ["obliquity change"] * has_obliquity + ["period residual", "wobble"]
    else:
        has_periods = "P_psi" in table.colnames
        panels = ["periods"] * has_periods + ["pole"] + ["obliquity"] * has_obliquity + ["mode"] * has_periods
    ratios = [3 if p != "mode" else 0.6 for p in panels]
    figure = Figure(figsize=(8, 1.2 + 1.9 * len(panels)), layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.subplots(len(panels), 1, sharex=True, gridspec_kw={"height_ratios": ratios}, squeeze=False)[:, 0]
    dates = _dates(table["time"])
    by_name = dict(zip(panels, axes))
    if principal:
        _principal_axis_panels(table, dates, by_name)
    else:
        _tumbler_panels(table, dates, by_name)
    marks = [(name, approach) for name, found in (encounters or {}).items()
             for approach in (found if isinstance(found, list) else [found])]
    for name, approach in marks:
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


def _tumbler_panels(table, dates, by_name):
    """Periods, pole, obliquity and the class strip of a table with tumbling rows (or no class at all)."""
    import numpy as np

    if "periods" in by_name:
        ax = by_name["periods"]
        for name, label in (("P_psi", "P_ψ"), ("P_phi", "P_φ"), ("sidereal_period", "sidereal")):
            if name in table.colnames:
                values = _values(table[name], "h")  # masked (PA) rows and infinite P_ψ are gaps
                if np.any(np.isfinite(values)):
                    ax.plot(dates, np.where(np.isfinite(values), values, np.nan), label=label)
        ax.set_ylabel("period [h]")
        ax.legend(loc="best", fontsize="small")
    ax = by_name["pole"]
    ax.plot(dates, _values(table["pole_lon"], "deg"), label="λ (ecliptic J2000)")
    ax.plot(dates, _values(table["pole_lat"], "deg"), label="β")
    ax.set_ylabel("pole [deg]")
    ax.legend(loc="best", fontsize="small")
    if "obliquity" in by_name:
        by_name["obliquity"].plot(dates, _values(table["obliquity"], "deg"), color="C4")
        by_name["obliquity"].set_ylabel("obliquity [deg]")
    if "mode" in by_name:
        ax = by_name["mode"]
        column = "rotation_class" if "rotation_class" in table.colnames else "mode"
        classes = np.asarray(table[column]).astype(str)
        edges = np.concatenate([dates[:1], 0.5 * (dates[1:] + dates[:-1]), dates[-1:]]) if len(dates) > 1 else \
            np.array([dates[0] - 0.5, dates[0] + 0.5])
        for name in sorted(set(classes)):
            for i in np.flatnonzero(classes == name):
                ax.axvspan(edges[i], edges[i + 1], color=MODE_COLOURS.get(name, "0.5"), lw=0)
            ax.plot([], [], color=MODE_COLOURS.get(name, "0.5"), lw=6, label=name)
        ax.set_yticks([])
        ax.set_ylabel("class" if column == "rotation_class" else "mode")
        ax.legend(loc="center left", bbox_to_anchor=(1.0, 0.5), fontsize="small", frameon=False)


def pole_offsets_arcsec(table):
    """(east, north) offsets (arcsec) of each row's pole from the first row's, on the ecliptic sky.

    The pole's unit vector projected on the plane tangent at the start pole (east: increasing λ, north:
    increasing β); for the arcsec drifts of a principal-axis rotator these are Δλ cos β and Δβ.
    """
    import numpy as np

    lon, lat = (np.radians(_values(table[name], "deg")) for name in ("pole_lon", "pole_lat"))
    poles = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=1)
    east = np.array([-np.sin(lon[0]), np.cos(lon[0]), 0.0])
    north = np.array([-np.sin(lat[0]) * np.cos(lon[0]), -np.sin(lat[0]) * np.sin(lon[0]), np.cos(lat[0])])
    return (np.degrees(np.arcsin(np.clip(poles @ axis, -1.0, 1.0))) * ARCSEC_PER_DEG for axis in (east, north))


def _principal_axis_panels(table, dates, by_name):
    """What changes in a principal-axis rotator's run: pole drift, obliquity, sidereal period, wobble."""
    east, north = pole_offsets_arcsec(table)
    ax = by_name["pole drift"]
    ax.plot(dates, east, label="east, Δλ cos β")
    ax.plot(dates, north, label="north, Δβ")
    lon0, lat0 = (_values(table[name], "deg")[0] for name in ("pole_lon", "pole_lat"))
    ax.set_ylabel("pole drift [arcsec]")
    ax.legend(loc="best", fontsize="small", title=f"from λ = {lon0:.4f}°, β = {lat0:.4f}°", title_fontsize="small")
    if "obliquity change" in by_name:
        obliquity = _values(table["obliquity"], "deg")
        ax = by_name["obliquity change"]
        ax.plot(dates, (obliquity - obliquity[0]) * ARCSEC_PER_DEG, color="C4")
        ax.set_ylabel(f"obliquity − {obliquity[0]:.4f}°\n[arcsec]")
    period = _values(table["sidereal_period"], "s")
    ax = by_name["period residual"]
    ax.plot(dates, (period - period[0]) * 1e3, color="C5")
    ax.set_ylabel(f"P − {period[0] / 3600.0:.6f} h\n[ms]")
    ax = by_name["wobble"]
    ax.plot(dates, _values(table["wobble_amplitude"], "arcsec"), color="C2")
    threshold = table.meta.get("pa_threshold", "")
    ax.set_ylabel("wobble\namplitude [arcsec]")
    ax.annotate(f"PA in every row (threshold {threshold})", (0.01, 0.9), xycoords="axes fraction", fontsize="small",
                va="top")


def _values(column, unit):
    """Plain floats of a column in ``unit``; masked entries (P_ψ, P_φ of PA rows) are NaN, i.e. gaps in a plot."""
    import numpy as np

    values = column.to_value(unit) if hasattr(column, "to_value") else column
    if hasattr(values, "unmasked"):  # astropy Masked
        return np.where(values.mask, np.nan, np.asarray(values.unmasked, dtype=float))
    return np.ma.filled(np.ma.asarray(values, dtype=float), np.nan)
