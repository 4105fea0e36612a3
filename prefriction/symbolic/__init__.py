"""Public CasADi view of the friction models and of the simulator's plant.

- :func:`branch_functions`: for a model and a branch direction, the CasADi Functions of the
  state rate, the force, the event indicators, the in-branch event maps and the reset at a
  reversal (:class:`BranchFunctions`);
- :func:`plant_step`: the event-locating plant of :func:`prefriction.simulate` over one step of
  constant force, a ``casadi.Function`` of the state, the model's numbers, the force, the step
  and the tolerance, callable inside a user's NLP;
- :func:`branch_model`: the stage on one branch as named expressions ``x``, ``xdot``, ``u``,
  ``p``, ``f_expl_expr`` (the naming of acados' ``AcadosModel`` and do-mpc), with the reversal map
  (:class:`BranchModel`).

All in the normalised units of :class:`prefriction.Scales`; see ``docs/symbolic.md``.
"""

from prefriction.symbolic.branch import BranchFunctions, branch_functions
from prefriction.symbolic.model import BranchModel, branch_model
from prefriction.symbolic.plant import plant_step

__all__ = ["BranchFunctions", "BranchModel", "branch_functions", "branch_model", "plant_step"]
