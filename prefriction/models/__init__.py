"""Friction models behind one protocol, and the oscillator (2.1) they act in.

- :class:`FrictionModel` (``base.py``): the contract every model implements (``docs/models.md``);
- :class:`Dahl` (``dahl.py``): the Dahl model (3.2) of the paper;
- :class:`MaxwellSlip` (``maxwell_slip.py``): N elasto-plastic elements (Iwan; Lampaert et al.);
- :class:`LuGre` (``lugre.py``): the LuGre model (Canudas de Wit et al. 1995);
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
from prefriction.models.gms import GMS
from prefriction.models.lugre import LuGre
from prefriction.models.maxwell_slip import MaxwellSlip
from prefriction.models.parallel import Parallel
from prefriction.models.viscous import Viscous
from prefriction.models.directional import DirectionalViscous
from prefriction.models.oscillator import Oscillator, check_dahl_oscillator, check_oscillator

__all__ = ["Dahl", "DirectionalViscous", "FrictionModel", "GMS", "LuGre", "MaxwellSlip", "Oscillator", "Parallel", "Parameter", "Viscous",
           "check_dahl_oscillator", "check_oscillator"]
