"""`housingfe radiation foller <table>`: Föller's box estimate (Sec. 4.7) with the Appendix E quantities,
L_sigma(f) as CSV and a PNG like Fig. 4.23/4.24."""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from housingfe import levels
from housingfe.errors import InputError
from housingfe.outputs import atomic_output_dir, format_table, reserve_output, write_csv, write_json
from housingfe.radiation import foller

# Quantity name in FollerResult -> (key in the published table, label, format)
APPENDIX_E_ROWS = (
    ("S_mean", "S_mean_m2", "mean plate area S_p [m^2]", "{:.4f}"),
    ("U_mean", "U_mean_m", "mean perimeter U [m]", "{:.3f}"),
    ("fc_mean", "fc_mean_Hz", "mean critical frequency f_c [Hz] (4.12)", "{:.1f}"),
    ("sigma_P", "sigma_P_at_fc_mean", "sigma'_P(f_c) (4.11)", "{:.3f}"),
    ("point_P_dB", "point_P_dB", "point P [dB]", "{:.2f}"),
    ("zero_dB_crossing_hz", "zero_dB_crossing_Hz", "0 dB crossing [Hz]", "{:.1f}"),
    ("L_125", "index_at_125Hz_dB", "L_sigma at 125 Hz [dB]", "{:.2f}"),
    ("compactness_lhs", "compactness_lhs", "c^2/(S_p f_c^2) (4.15) [> 1.31]", "{:.3f}"),
)


def appendix_e_rows(result: foller.FollerResult, published: dict | None):
    """(label, ours, printed) rows of the Appendix E quantities; printed is '' without a reference."""
    rows = []
    for attr, key, label, fmt in APPENDIX_E_ROWS:
        value = float(result.index_db(125.0)) if attr == "L_125" else getattr(result, attr)
        printed = published.get(key, "") if published else ""
        rows.append((label, fmt.format(value), printed))
    return rows


def _plot(path: Path, result: foller.FollerResult, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    f = np.geomspace(50.0, 10000.0, 400)
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.semilogx(f, foller.piston_line_db(f, result.fc_mean, result.point_P_dB), "k-",
                label="equivalent piston (25 dB/decade through P, capped at 0 dB)")
    ax.semilogx(f, 10 * np.log10(foller.mean_plate_sigma(f, result.plates, None, result.c)), "k--",
                label="plates with acoustic cancellation (4.13, 4.14)")
    ax.semilogx(f, result.index_db(f), "r-", lw=2, alpha=0.6,
                label="estimate" + (" (compact: piston only)" if result.is_compact else " (minimum)"))
    construction = f[f <= result.fc_mean]
    ax.semilogx(construction, result.point_P_dB + foller.SLOPE_DB_PER_DECADE * np.log10(construction / result.fc_mean),
                "k:", lw=0.8)
    ax.plot([result.fc_mean], [result.point_P_dB], "ko")
    ax.annotate(f"P ({result.fc_mean:.0f} Hz, {result.point_P_dB:.1f} dB)",
                (result.fc_mean, result.point_P_dB), textcoords="offset points", xytext=(5, 5))
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("radiation index L_sigma [dB]")
    ax.set_ylim(-25, 5)
    ax.grid(True, which="both", alpha=0.3)
    ax.set_title(title)
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def cmd_foller(args: argparse.Namespace) -> int:
    """Print the Appendix E quantities of a plate table, write foller.csv, foller.png, summary.json."""
    plates, c = foller.load_plate_table(args.table)
    if not 0 < args.fmin < args.fmax:
        raise InputError("--fmin/--fmax: need 0 < fmin < fmax (Hz)")
    # the default folder is named after the table, not its path (`/x/plates.toml` made results/radiation-foller-/x/plates)
    out = Path(args.out or f"results/radiation-foller-{Path(args.table.replace('builtin:', '')).stem}")
    # a refused --out stops before the table is printed (it read as a finished run followed by an error)
    reserve_output(out, inputs=[] if args.table.startswith("builtin:") else [args.table])
    bands = levels.third_octave_bands(args.fmin, args.fmax)
    result = foller.foller_radiation_index(plates, bands.center, c=c)
    published = None
    if args.table.startswith("builtin:"):
        published = foller.published_appendix_e(foller.BUILTIN_TABLES[args.table.split(":", 1)[1]])
    rows = appendix_e_rows(result, published)
    print(f"Föller box estimate for {args.table} ({sum(p.count for p in plates)} plates, c = {c:g} m/s)")
    print(format_table(["quantity", "ours", "printed (App. E)" if published else ""], rows))
    print(f"compact (eq. 4.15): {'yes' if result.is_compact else 'no'}; slope 25 dB/decade "
          "(App. E prints 'dB/octave'; its numbers follow from dB/decade)")
    with atomic_output_dir(out) as tmp:
        write_csv(tmp / "foller.csv",
                  ["band_nominal_hz", "band_center_hz", "L_piston_db", "L_plates_db", "L_sigma_db"],
                  [(n, f"{f:.2f}", f"{a:.2f}", f"{b:.2f}", f"{s:.2f}") for n, f, a, b, s in
                   zip(bands.nominal, bands.center, result.L_piston_db, result.L_plates_db, result.L_sigma_db)])
        write_json(tmp / "summary.json", {
            "table": args.table, "c_m_s": c, "is_compact": result.is_compact,
            **{attr: (float(result.index_db(125.0)) if attr == "L_125" else getattr(result, attr))
               for attr, *_ in APPENDIX_E_ROWS},
            "published": {k: v for k, v in (published or {}).items() if k != "plates"}})
        _plot(tmp / "foller.png", result, f"Föller box estimate: {args.table}")
    print(f"wrote {out}/foller.csv, foller.png, summary.json")
    return 0


def register(subparsers) -> None:
    """`housingfe radiation foller ...`."""
    p = subparsers.add_parser("radiation", help="radiation efficiency estimates (Sec. 4.7)")
    sub = p.add_subparsers(dest="radiation_command", required=True)
    q = sub.add_parser("foller", help="Föller's box model from a plate table (Appendix E)")
    q.add_argument("table", help="TOML file with plates = [...], or builtin:scale-model / builtin:test-gearbox")
    q.add_argument("--out", default=None, help="result folder (default results/radiation-foller-<name>)")
    q.add_argument("--fmin", type=float, default=50.0, help="lowest 1/3-octave band centre [Hz]")
    q.add_argument("--fmax", type=float, default=10000.0, help="highest 1/3-octave band centre [Hz]")
    q.set_defaults(func=cmd_foller, mpi="serial")
