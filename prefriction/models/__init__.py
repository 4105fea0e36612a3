"""Friction models behind one protocol, and the oscillator (2.1) they act in.

- :class:`FrictionModel` (``base.py``): the contract every model implements (``docs/models.md``),
  with the bookkeeping it derives from a model's mathematics in ``defaults.py``;
- :class:`Dahl` (``dahl.py``): the Dahl model (3.2) of the paper, its branch functions for any
  gamma in ``dahl_branch.py`` (public as :mod:`prefriction.analysis.branch`);
- :class:`MaxwellSlip` (``maxwell_slip.py``): N elastic-plastic (Jenkin) elements (Iwan; Lampaert et al.);
- :class:`LuGre` (``lugre.py``): the LuGre model (Canudas de Wit et al. 1995);
- :class:`ElastoPlastic` (``elasto_plastic.py``): the single-state elasto-plastic model (Dupont et al. 2002);
- :class:`GMS` (``gms.py``): the generalised Maxwell-slip model (Al-Bender et al. 2005);
- ``elements.py``: the element machinery Maxwell-slip and GMS share
  (:class:`~prefriction.models.elements.ParallelElements`);
- ``element_curves.py``: the virgin curve of parallel elements and the energies on its branches;
- ``stribeck.py``: the Stribeck curve of GMS, in SI units and normalised;
- :class:`Viscous` (``viscous.py``): viscous friction ``F = b v``;
- :class:`DirectionalViscous` (``directional.py``): a viscous coefficient per direction;
- :class:`Parallel` (``parallel.py``): models in parallel, ``a + b`` (forces summed);
- :class:`Oscillator` (``oscillator.py``): mass, friction model and input force.
"""

from prefriction.models.base import FrictionModel, Parameter
from prefriction.models.dahl import Dahl
from prefriction.models.elasto_plastic import ElastoPlastic
from prefriction.models.gms import GMS
from prefriction.models.lugre import LuGre
from prefriction.models.maxwell_slip import MaxwellSlip
from prefriction.models.parallel import Parallel
from prefriction.models.viscous import Viscous
from prefriction.models.directional import DirectionalViscous
from prefriction.models.oscillator import Oscillator, check_dahl_oscillator, check_oscillator

__all__ = ["Dahl", "DirectionalViscous", "ElastoPlastic", "FrictionModel", "GMS", "LuGre", "MaxwellSlip", "Oscillator",
           "Parallel", "Parameter", "Viscous",
           "check_dahl_oscillator", "check_oscillator"]
