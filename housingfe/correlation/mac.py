"""Mode correlation: MAC, mass cross-orthogonality, automatic pairing, frequency-error table, MAC picture.

Shapes are columns of (channels x modes) arrays sampled on the same channels (measured point and direction);
they may be real or complex and have any scale (MAC is scale-free).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from housingfe.errors import InputError


def mac(phi_a: np.ndarray, phi_b: np.ndarray) -> np.ndarray:
    """Modal assurance criterion MAC_ij = |a_i^H b_j|^2 / ((a_i^H a_i)(b_j^H b_j)), shape (modes_a, modes_b),
    between the columns of phi_a (channels x modes_a) and phi_b (channels x modes_b); 1 for parallel shapes,
    0 for orthogonal ones.  A zero column gives 0 (it correlates with nothing)."""
    a = np.atleast_2d(np.asarray(phi_a))
    b = np.atleast_2d(np.asarray(phi_b))
    if a.shape[0] != b.shape[0]:
        raise InputError(f"mac: the shapes have {a.shape[0]} and {b.shape[0]} channels; they must share channels")
    num = np.abs(a.conj().T @ b) ** 2
    den = np.outer(np.sum(np.abs(a) ** 2, axis=0), np.sum(np.abs(b) ** 2, axis=0))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)


def cross_orthogonality(phi_a: np.ndarray, phi_b: np.ndarray, mass) -> np.ndarray:
    """Normalised mass cross-orthogonality CO_ij = a_i^T M b_j / sqrt((a_i^T M a_i)(b_j^T M b_j)) (signed, real
    shapes; |CO| = 1 for the same mode, 0 for M-orthogonal modes).  mass: a (channels x channels) matrix
    (dense, scipy.sparse, or anything with @), e.g. the FE mass matrix (kg) or a reduced (SEREP/Guyan) one."""
    a = np.atleast_2d(np.asarray(phi_a, float))
    b = np.atleast_2d(np.asarray(phi_b, float))
    ma, mb = mass @ a, mass @ b
    num = a.T @ mb
    na = np.sqrt(np.abs(np.einsum("ij,ij->j", a, ma)))
    nb = np.sqrt(np.abs(np.einsum("ij,ij->j", b, mb)))
    return num / np.outer(na, nb)


@dataclass
class Pair:
    """One paired mode: measured index, computed index (0-based), MAC, frequencies (Hz), relative error
    (f_computed - f_measured) / f_measured."""

    measured: int
    computed: int
    mac: float
    f_measured: float
    f_computed: float

    @property
    def error(self) -> float:
        return (self.f_computed - self.f_measured) / self.f_measured


@dataclass
class Pairing:
    """Result of pair_modes: the pairs (ordered by measured mode), the unpaired measured and computed mode
    indices, the threshold used and the MAC matrix (measured x computed)."""

    pairs: list
    unpaired_measured: list
    unpaired_computed: list
    threshold: float
    mac: np.ndarray

    def table(self) -> list[tuple]:
        """Rows (measured #, f_meas Hz, computed #, f_comp Hz, error %, MAC), 1-based mode numbers."""
        return [(p.measured + 1, p.f_measured, p.computed + 1, p.f_computed, 100 * p.error, p.mac)
                for p in self.pairs]

    def mean_abs_error(self) -> float:
        """Mean |relative frequency error| of the pairs (fraction)."""
        return float(np.mean([abs(p.error) for p in self.pairs])) if self.pairs else float("nan")

    def format(self) -> str:
        from housingfe.outputs import format_table

        rows = [(m, f"{fm:.1f}", c, f"{fc:.1f}", f"{e:+.2f}", f"{v:.3f}") for m, fm, c, fc, e, v in self.table()]
        text = format_table(["meas", "f_meas Hz", "comp", "f_comp Hz", "error %", "MAC"], rows)
        text += f"\npaired {len(self.pairs)} (MAC >= {self.threshold:g}), mean |error| " \
                f"{100 * self.mean_abs_error():.2f} %"
        text += f"\nunpaired measured: {[i + 1 for i in self.unpaired_measured]}"
        text += f"\nunpaired computed: {[i + 1 for i in self.unpaired_computed]}"
        return text


def pair_modes(mac_matrix: np.ndarray, f_measured, f_computed, threshold: float = 0.6,
               frequency_weight: float = 0.0) -> Pairing:
    """Pair measured with computed modes by an optimal assignment (scipy.optimize.linear_sum_assignment)
    maximising the summed MAC, each mode used at most once; assignments with MAC < threshold are dropped
    and listed as unpaired.  frequency_weight > 0 subtracts w * |ln(f_c / f_m)| from the score, which
    separates the members of close pairs whose shapes are spatially aliased on few channels."""
    from scipy.optimize import linear_sum_assignment

    m = np.asarray(mac_matrix, float)
    fm, fc = np.asarray(f_measured, float), np.asarray(f_computed, float)
    if m.shape != (len(fm), len(fc)):
        raise InputError(f"pair_modes: MAC matrix {m.shape} does not match {len(fm)} measured and "
                         f"{len(fc)} computed frequencies")
    score = m.copy()
    if frequency_weight > 0:
        with np.errstate(divide="ignore"):
            score -= frequency_weight * np.abs(np.log(np.maximum(fc[None, :], 1e-30) / np.maximum(fm[:, None], 1e-30)))
    rows, cols = linear_sum_assignment(score, maximize=True)
    pairs = [Pair(int(i), int(j), float(m[i, j]), float(fm[i]), float(fc[j]))
             for i, j in zip(rows, cols) if m[i, j] >= threshold]
    paired_m = {p.measured for p in pairs}
    paired_c = {p.computed for p in pairs}
    return Pairing(sorted(pairs, key=lambda p: p.measured), [i for i in range(len(fm)) if i not in paired_m],
                   [j for j in range(len(fc)) if j not in paired_c], threshold, m)


def mac_png(mac_matrix: np.ndarray, path: str | Path, f_measured=None, f_computed=None, pairing: Pairing | None = None,
            title: str = "MAC") -> Path:
    """A MAC matrix picture (measured rows x computed columns, grey scale 0..1, pairs circled) as PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    m = np.asarray(mac_matrix, float)
    fig, ax = plt.subplots(figsize=(1.5 + 0.22 * m.shape[1], 1.2 + 0.22 * m.shape[0]), dpi=110)
    im = ax.imshow(m, cmap="Greys", vmin=0.0, vmax=1.0, origin="upper", aspect="auto")
    if pairing is not None:
        for p in pairing.pairs:
            ax.plot(p.computed, p.measured, "o", mfc="none", mec="tab:red", ms=7)
    ax.set_xlabel("computed mode" + (" (Hz)" if f_computed is not None else ""))
    ax.set_ylabel("measured mode" + (" (Hz)" if f_measured is not None else ""))
    if f_computed is not None:
        ax.set_xticks(range(m.shape[1]), [f"{f:.0f}" for f in f_computed], rotation=90, fontsize=6)
    if f_measured is not None:
        ax.set_yticks(range(m.shape[0]), [f"{f:.0f}" for f in f_measured], fontsize=6)
    ax.set_title(title, fontsize=9)
    fig.colorbar(im, ax=ax, fraction=0.04)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path)
    plt.close(fig)
    return path


def frac(h_measured: np.ndarray, h_computed: np.ndarray) -> float:
    """Frequency response assurance criterion of one FRF pair on the same lines:
    |h_m^H h_c|^2 / ((h_m^H h_m)(h_c^H h_c)), 1 for proportional FRFs."""
    a, b = np.asarray(h_measured).ravel(), np.asarray(h_computed).ravel()
    if a.shape != b.shape:
        raise InputError(f"frac: {a.size} and {b.size} lines; interpolate to the same lines first")
    den = float(np.vdot(a, a).real * np.vdot(b, b).real)
    return float(abs(np.vdot(a, b)) ** 2 / den) if den > 0 else 0.0
