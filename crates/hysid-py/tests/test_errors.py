"""Bad input raises a Python exception with a clear one-line message, never a crash."""

import hysid
import numpy as np
import pytest
from conftest import BW_TRUTH, FS
from models import bouc_wen_python, bw_output, raising_rhs, wrong_shape_late

X = np.sin(np.linspace(0, 20, 300)) * 3


def cascade(x, y, **kw):
    return hysid.identify_cascade(x, y, **{"na": 2, "nb": 2, "delay": 1, **kw})


def test_wrong_shape():
    with pytest.raises(ValueError, match=r"y: expected a 1-D array, got shape \(300, 2\)"):
        cascade(X, np.zeros((300, 2)))


def test_length_mismatch():
    with pytest.raises(hysid.DataError, match="x has 300 samples and y 299"):
        cascade(X, X[:-1])


def test_nan():
    y = X.copy()
    y[17] = np.nan
    with pytest.raises(ValueError, match="y: sample 17 is nan, not finite"):
        cascade(X, y)


def test_empty():
    with pytest.raises(hysid.DataError, match="empty"):
        cascade(np.array([]), np.array([]))


def test_wrong_type():
    with pytest.raises(TypeError, match="x: expected a numeric array, got str"):
        cascade("abc", X)
    with pytest.raises(TypeError, match="na: expected an integer"):
        cascade(X, X, na=2.5)


def test_library_error_is_one_line():
    with pytest.raises(hysid.HysidError) as e:
        cascade(X, X, hysteresis="ch9")
    assert "\n" not in str(e.value) and "panicked" not in str(e.value)
    assert isinstance(e.value, ValueError)


def test_too_few_samples():
    with pytest.raises(hysid.HysidError, match="sample"):
        cascade(X[:5], X[:5])


def test_unknown_model_and_parameter():
    with pytest.raises(hysid.ConfigError, match="unknown grey-box model 'pendulum'"):
        hysid.greybox_fit("pendulum", X, X, ts=0.01)
    with pytest.raises(hysid.ConfigError, match="no parameter 'zeta'"):
        hysid.greybox_fit("bouc-wen", X, X, ts=0.01, init={"zeta": 1.0})


def test_callback_raises_at_construction():
    with pytest.raises(hysid.CallbackError, match=r"rhs\(t, x, u, p\) raised ZeroDivisionError"):
        hysid.GreyBoxModel(["y"], [hysid.Parameter("k", 1.0)], lambda t, x, u, p: 1 / 0, bw_output)


def test_callback_wrong_shape_at_construction():
    with pytest.raises(hysid.CallbackError, match=r"returned shape \(2,\); it must return \(3,\)"):
        hysid.GreyBoxModel(["y", "v", "z"], [hysid.Parameter("k", 1.0)], lambda t, x, u, p: np.zeros(2), bw_output)


def _user(rhs):
    m = bouc_wen_python(BW_TRUTH)
    m.rhs = rhs
    return m


def test_callback_raises_during_fit():
    u = np.sin(np.arange(200) / 10) * 50
    with pytest.raises(hysid.CallbackError, match=r"rhs\(t, x, u, p\) raised ZeroDivisionError: boom") as e:
        hysid.greybox_fit(_user(raising_rhs), u, np.sin(np.arange(200) / 7), ts=1 / FS, substeps=1)
    assert isinstance(e.value.__cause__, ZeroDivisionError)


def test_callback_wrong_shape_during_fit():
    u = np.sin(np.arange(200) / 10) * 50
    with pytest.raises(hysid.CallbackError, match=r"returned 2 values; it must return 3"):
        hysid.greybox_fit(_user(wrong_shape_late), u, np.sin(np.arange(200) / 7), ts=1 / FS, substeps=1)


def test_bad_model_file(tmp_path):
    p = tmp_path / "bad.json"
    p.write_text('{"schema": "nope"}')
    with pytest.raises(hysid.HysidError):
        hysid.load_model(p)
    with pytest.raises(hysid.ModelFileError):
        hysid.load_model(tmp_path / "missing.json")


def test_simulate_bad_input():
    m = hysid.load_model(__import__("conftest").DATA / "example1_cli_model.json")
    with pytest.raises(ValueError, match="not finite"):
        m.simulate(np.array([0.0, np.inf]), ts=1.0)
    with pytest.raises(hysid.ConfigError, match="positive"):
        m.simulate(X, ts=-1.0)
