"""benchmark_bouc_wen on the shared training record reproduces the CLI's figures
(`hysid benchmark bouc-wen --train train_multisine_5periods.csv`, in
data/bouc_wen_cli_figures.json). Needs the project's shared data (beside the clone, or
HYSID_SHARED=path/to/shared)."""

import json
import os
import pathlib

import hysid
import numpy as np
import pytest
from conftest import DATA


def shared_record():
    roots = [os.environ.get("HYSID_SHARED")] + [str(p / "shared") for p in pathlib.Path(__file__).resolve().parents]
    for root in filter(None, roots):
        path = pathlib.Path(root) / "data" / "bouc-wen" / "train_multisine_5periods.csv"
        if path.exists():
            return path
    return None


@pytest.mark.slow
@pytest.mark.skipif(shared_record() is None, reason="the shared Bouc–Wen training record is not here")
def test_benchmark_reproduces_cli():
    d = np.loadtxt(shared_record(), delimiter=",", skiprows=1)
    u, y, ts = d[:, 1], d[:, 2], d[1, 0] - d[0, 0]
    r = hysid.benchmark_bouc_wen(u, y, ts=ts)
    cli = json.loads((DATA / "bouc_wen_cli_figures.json").read_text())
    for name, value in cli["parameters"].items():
        assert abs(r.parameters[name].value - value) <= 1e-12 * abs(value), name
    assert abs(r.fit_percent - cli["fit_percent"]) < 1e-9
    assert abs(r.report()["details"]["training_e_rms"] - cli["training_e_rms"]) < 1e-15
    print(
        f"\nBouc–Wen benchmark: training e_RMS {cli['training_e_rms']:.4e} m, fit {r.fit_percent:.2f} %, "
        f"fit time {r.elapsed_s:.2f} s"
    )
