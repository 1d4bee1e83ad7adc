"""``render_mode="rgb_array"``: the identification error so far against gamma(N)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .config import AttackParams


def render_error_curve(core: Any, params: AttackParams, design: Any = None, size: tuple[int, int] = (640, 420)) -> np.ndarray:
    """Draw epsilon(N) of the delivered data with gamma(N) (eq:sic) and gamma_opt(N).

    Returns
    -------
    numpy.ndarray
        ``(height, width, 3)`` uint8 image.
    """
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    dpi = 100
    fig = Figure(figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi)
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    hist = [(N, e) for N, e in core.history if N - 1 >= core.d]
    N_max = params.horizon
    Ns = np.unique(np.geomspace(max(core.d + 1, 2), max(N_max, core.d + 2), 200).astype(int))
    ax.loglog(Ns, core.gamma_table[Ns], "--", color="tab:orange", label=r"$\gamma(N)$ (eq:sic)")
    if design is not None:
        ax.loglog(Ns, core.gamma_opt_table[Ns], ":", color="tab:green", label=r"$\gamma_{opt}(N)$")
    if hist:
        N, e = zip(*hist)
        ax.loglog(N, e, "-", color="tab:blue", label=r"$\epsilon(N)$ so far")
    ax.axhline(params.gamma_c, color="gray", lw=0.8, label=r"$\gamma_c$")
    ax.set_xlabel("samples delivered N")
    ax.set_ylabel("identification error")
    ax.set_title(f"{params.scheme} scheme, lambda = {params.security_parameter:g} bit, N <= {N_max}")
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    canvas.draw()
    img = np.asarray(canvas.buffer_rgba())[:, :, :3]
    return np.ascontiguousarray(img)
