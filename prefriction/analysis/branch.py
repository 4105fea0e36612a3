"""Branch functions of the Dahl model (3.2) for any ``gamma >= 0``: the public path of
:mod:`prefriction.models.dahl_branch`, where they live beside the model (models never import
from the analysis)."""

from prefriction.models.dahl_branch import *  # noqa: F401,F403
from prefriction.models.dahl_branch import __all__  # noqa: F401
