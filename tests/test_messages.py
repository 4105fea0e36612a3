"""Bad-input messages read as plain numbers, and refusals come without numpy warnings first."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from prefriction.analysis import dahl
from prefriction.describing import dahl_cycle, dahl_describing_function


@pytest.mark.parametrize("A, shown", [(np.float64("nan"), "nan"), ([1e-6, np.float64("inf")], "inf"),
                                      (np.float64(-2.0), "-2.0")])
@pytest.mark.parametrize("func", [dahl_describing_function, dahl_cycle])
def test_amplitude_message_shows_a_plain_float(func, A, shown):
    with pytest.raises(ValueError, match=r"A must lie in \[0, inf\)") as exc:
        func(A, 1.0e4, 1.0)
    assert str(exc.value).endswith(f"got {shown}")
    assert "np.float64" not in str(exc.value)


@pytest.mark.parametrize("func", [dahl.branch_energy, dahl.omega])
def test_huge_position_refused_without_overflow_warning(func):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a RuntimeWarning before the refusal would fail here
        with pytest.raises(ValueError, match=r"x = 1e\+305 m is too large .* overflows"):
            func(1e305, 1.0e10, 1.0e-3)
