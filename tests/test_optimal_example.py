"""examples/optimal_move.py runs (quick: the Dahl stage) and its figure and table hold what it claims."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import matplotlib
import pytest

matplotlib.use("Agg")

pytestmark = pytest.mark.slow  # an example script end to end: .ci/run's second command (-m slow)

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "optimal_move.py"


def test_optimal_move_example(tmp_path):
    spec = importlib.util.spec_from_file_location("optimal_move_example", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    out = module.main(tmp_path, quick=True)
    assert out["png"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out["png"].stat().st_size > 50_000
    for name, r in out["dahl"].items():
        if name.startswith("pre-sliding"):
            assert abs(r.replay.x_error) <= 1e-9
        else:
            assert abs(r.replay.x_error) > 1e-5  # tens of micrometres off
    assert out["table"].count("\n") == 1 + len(out["dahl"])
