"""Optimal point-to-point motion through pre-sliding friction (CasADi and IPOPT).

- :func:`point_to_point`: minimum-time or minimum-effort move of a stage with a force limit, as
  a multi-phase problem (one velocity sign per phase, the switching times free) that keeps the
  friction model's reversals; its force replayed through :func:`prefriction.simulate`;
- :func:`smoothed_point_to_point`: the same problem with tanh-smoothed Coulomb friction, the
  usual shortcut, and :func:`bang_bang`: the closed-form Coulomb profile; both replayed with the
  real friction model, to show how far they miss;
- :func:`replay`: drive a stage with a force through :func:`prefriction.simulate`.

See ``docs/optimal.md``.
"""

from prefriction.optimal.problem import point_to_point
from prefriction.optimal.references import bang_bang, smoothed_point_to_point
from prefriction.optimal.replay import Replay, replay
from prefriction.optimal.result import PointToPointResult

__all__ = ["PointToPointResult", "Replay", "bang_bang", "point_to_point", "replay", "smoothed_point_to_point"]
