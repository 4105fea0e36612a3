"""A shooting segment's exact derivatives beside central finite differences of the segment itself
(the check both Motion-sensitivity test files make: exact where the motion is piecewise smooth)."""

from __future__ import annotations

from typing import Any

import numpy as np


def segment_derivatives(plain: Any, sens: Any, node: np.ndarray, theta: np.ndarray, args: dict
                        ) -> tuple[dict, np.ndarray, np.ndarray]:
    """The sensitivity Function's output ``o``, its derivatives ``ad`` of the segment's positions
    and event outputs (rows: ``X[0]`` at each sample, then ``Ye``; columns: ``theta`` then
    ``node``) and the central differences ``fd`` of ``plain`` in the same layout (step
    ``1e-6 max(1, |w_j|)`` in the scaled coordinates ``w``)."""
    nth = theta.size
    w = np.r_[theta, node]

    def out(ww: np.ndarray) -> np.ndarray:
        o = plain(node=ww[nth:], theta=ww[:nth], **args)
        return np.r_[np.asarray(o["X"])[0], np.asarray(o["Ye"]).ravel()]

    o = sens(node=node, theta=theta, **args)
    ad = np.vstack([np.asarray(o["dX"]).T, np.asarray(o["dYe"])])
    fd = np.empty_like(ad)
    for j in range(w.size):
        h = 1e-6 * max(1.0, abs(w[j]))
        fd[:, j] = (out(w + h * np.eye(w.size)[j]) - out(w - h * np.eye(w.size)[j])) / (2.0 * h)
    return o, ad, fd
