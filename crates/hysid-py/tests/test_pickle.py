"""Results and models pickle and round-trip exactly."""

import pickle

import hysid
import numpy as np
from conftest import FS
from models import bouc_wen_python
from test_greybox import START, short_record  # noqa: F401


def test_result_pickles_exactly(example1):
    r = hysid.identify_cascade(*example1, na=2, nb=2, delay=1)
    back = pickle.loads(pickle.dumps(r))
    assert back == r and back.report() == r.report()  # exact, elapsed time included
    for n, p in r.parameters.items():
        assert back.parameters[n].value == p.value and back.parameters[n].std == p.std
    x = example1[0]
    np.testing.assert_array_equal(back.model.simulate(x, ts=1.0), r.model.simulate(x, ts=1.0))


def test_model_and_parameter_pickle():
    p = hysid.Parameter("k", 0.1 + 0.2, lower=0.0, unit="N/m", std=1e-17)
    assert pickle.loads(pickle.dumps(p)) == p
    m = hysid.load_model(__import__("conftest").DATA / "example1_cli_model.json")
    assert pickle.loads(pickle.dumps(m)) == m


def test_user_model_result_pickles(short_record):  # noqa: F811
    u, y = short_record
    r = hysid.greybox_fit(bouc_wen_python(START), u[:150], y[:150], ts=1 / FS, substeps=1)
    back = pickle.loads(pickle.dumps(r))
    assert back == r
    np.testing.assert_array_equal(back.model.simulate(u, ts=1 / FS), r.model.simulate(u, ts=1 / FS))
