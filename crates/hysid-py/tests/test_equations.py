"""GreyBoxModel.from_equations: equation-file models with exact sensitivities."""

import pathlib
import pickle

import hysid
import numpy as np
import pytest
from conftest import BW_TRUTH, FS, bouc_wen_model, rel_err

REPO = pathlib.Path(__file__).resolve().parents[3]
EXAMPLES = REPO / "examples" / "equations"
DUFFING_TRUTH = {"m": 1.5, "c": 0.4, "k": 2.0, "k3": 0.8}
TS = 0.05


def duffing_input(n=1200, seed=11):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * TS
    freqs = np.array([0.05, 0.11, 0.17, 0.23, 0.31, 0.42])
    phases = rng.uniform(0, 2 * np.pi, freqs.size)
    return 1.5 * np.sin(2 * np.pi * freqs[:, None] * t[None, :] + phases[:, None]).sum(axis=0)


@pytest.fixture(scope="module")
def duffing():
    return hysid.GreyBoxModel.from_equations_file(EXAMPLES / "duffing.toml")


@pytest.fixture(scope="module")
def duffing_record(duffing):
    truth = pickle.loads(pickle.dumps(duffing))
    for p in truth.parameters:
        p.value = DUFFING_TRUTH[p.name]
    u = duffing_input()
    return u, truth.simulate(u, ts=TS)


def test_model_from_the_file(duffing):
    assert duffing.equations is not None and duffing.name == "duffing"
    assert duffing.states == ["x", "v"] and duffing.inputs == 1 and duffing.outputs == 1
    assert [p.name for p in duffing.parameters] == ["m", "c", "k", "k3"]
    assert duffing.parameters[0].unit == "kg" and duffing.parameters[0].lower == 0.0
    assert "equations 'duffing'" in repr(duffing)


def test_duffing_recovered_to_1e_8(duffing, duffing_record):
    u, y = duffing_record
    assert np.ptp(y) > 1.0  # the cubic term is excited
    r = hysid.greybox_fit(duffing, u, y, ts=TS)
    for n, v in DUFFING_TRUTH.items():
        assert rel_err(r.parameters[n].value, v) < 1e-8, (n, r.parameters[n].value)
    rep = r.report()
    assert rep["command"] == "greybox fit" and rep["model"]["kind"] == "equations"
    assert rep["model"]["equations"] == duffing.equations
    assert r.converged


def test_fitted_equation_model_saves_loads_pickles(duffing, duffing_record, tmp_path):
    u, y = duffing_record
    r = hysid.greybox_fit(duffing, u, y, ts=TS)
    path = tmp_path / "duffing.model.json"
    r.model.save(path)
    back = hysid.load_model(path)
    assert back.kind == "equations" and back.file["equations"] == duffing.equations
    # The file is read by serde_json, whose default float parser may be 1 ulp off.
    for a, b in zip(back.file["parameters"], r.model.file["parameters"]):
        assert a["name"] == b["name"] and a["value"] == pytest.approx(b["value"], rel=1e-15, abs=0)
    np.testing.assert_allclose(back.simulate(u, ts=TS), y, rtol=0, atol=1e-9)
    again = pickle.loads(pickle.dumps(r))
    assert again == r and again.report() == r.report()
    model = pickle.loads(pickle.dumps(duffing))
    assert model.equations == duffing.equations and model.parameters == duffing.parameters


def test_bouc_wen_file_equals_the_builtin_model(bw_record):
    """The Bouc–Wen equation file fitted on the built-in model's data gives the built-in
    model's estimates to 1e-6."""
    u, y = bw_record
    start = {k: v * 1.05 for k, v in BW_TRUTH.items() if k != "nu"}
    eq = hysid.GreyBoxModel.from_equations_file(EXAMPLES / "bouc_wen.toml")
    a = hysid.greybox_fit(eq, u, y, ts=1 / FS, init=start, substeps=2)
    b = hysid.greybox_fit("bouc-wen", u, y, ts=1 / FS, init=start, substeps=2)
    for n in BW_TRUTH:
        assert rel_err(a.parameters[n].value, b.parameters[n].value) < 1e-6, n
        assert rel_err(a.parameters[n].value, BW_TRUTH[n]) < 1e-6, n
    # Same model, same simulation: the equation model reproduces the built-in one.
    eq_truth = eq.to_model(substeps=2)
    for p in eq_truth.file["parameters"]:
        p["value"] = BW_TRUTH[p["name"]]
    np.testing.assert_allclose(
        eq_truth.simulate(u, ts=1 / FS), bouc_wen_model().simulate(u, ts=1 / FS), rtol=0, atol=1e-12
    )


def test_malformed_text_names_line_and_column():
    text = (
        (EXAMPLES / "duffing.toml").read_text().replace('v = "(u - c*v - spring) / m"', 'v = "(u - c*v - sprung) / m"')
    )
    with pytest.raises(hysid.ConfigError) as e:
        hysid.GreyBoxModel.from_equations(text, origin="mine.toml")
    msg = str(e.value)
    assert isinstance(e.value, ValueError) and isinstance(e.value, hysid.HysidError)
    assert "mine.toml" in msg and "sprung" in msg and "line" in msg and "\n" not in msg
    with pytest.raises(hysid.ConfigError, match="line"):
        hysid.GreyBoxModel.from_equations('[model]\nstates = ["x"\n')
    with pytest.raises(TypeError):
        hysid.GreyBoxModel.from_equations(42)
    with pytest.raises(hysid.ModelFileError):
        hysid.GreyBoxModel.from_equations_file("/nonexistent/model.toml")


def test_equation_model_bad_data(duffing):
    with pytest.raises(hysid.DataError):
        hysid.greybox_fit(duffing, np.zeros((100, 2)), np.zeros(100), ts=TS)
    with pytest.raises(hysid.ConfigError, match="no parameter"):
        hysid.greybox_fit(duffing, np.ones(100), np.ones(100), ts=TS, init={"q": 1.0})


def test_equation_fit_uses_threads(duffing, duffing_record):
    u, y = duffing_record
    a = hysid.greybox_fit(duffing, u, y, ts=TS, threads=1)
    b = hysid.greybox_fit(duffing, u, y, ts=TS, threads=2)
    assert a.parameters == b.parameters


def test_the_evaluator_is_chosen_and_reported(duffing, duffing_record, tmp_path, monkeypatch):
    """evaluator= (the CLI's --evaluator): the tape and the C compiler's code give the same
    estimates and simulation to the bit, the report says which ran; a C route without a
    compiler, an unknown name and an evaluator for a built-in model are refused."""
    u, y = duffing_record
    monkeypatch.setenv("HYSID_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delenv("HYSID_EVALUATOR", raising=False)
    tape = hysid.greybox_fit(duffing, u, y, ts=TS, evaluator="tape")
    assert tape.report()["details"]["evaluation"] == "tape interpreter (evaluator tape chosen)"
    cc = hysid.greybox_fit(duffing, u, y, ts=TS, evaluator="cc")
    assert cc.report()["details"]["evaluation"].startswith("native code (compiled now: ")
    assert [p.value for p in cc.parameters.values()] == [p.value for p in tape.parameters.values()]
    again = hysid.greybox_fit(duffing, u, y, ts=TS)  # auto: the cached library
    assert again.report()["details"]["evaluation"] == "native code (loaded from the cache)"
    fitted = cc.model
    assert np.array_equal(fitted.simulate(u, ts=TS, evaluator="tape"), fitted.simulate(u, ts=TS, evaluator="cc"))
    monkeypatch.setenv("HYSID_EVALUATOR", "tape")  # the default when evaluator= is not given
    env = hysid.greybox_fit(duffing, u, y, ts=TS)
    assert env.report()["details"]["evaluation"] == "tape interpreter (evaluator tape chosen)"
    monkeypatch.setenv("HYSID_EVALUATOR", "jit")
    with pytest.raises(hysid.ConfigError, match="removed"):
        hysid.greybox_fit(duffing, u, y, ts=TS)
    monkeypatch.delenv("HYSID_EVALUATOR")
    monkeypatch.setenv("CC", "/nonexistent/cc")
    monkeypatch.setenv("HYSID_CACHE_DIR", str(tmp_path / "empty"))
    with pytest.raises(hysid.ConfigError, match="no native code for the evaluator 'cc'"):
        hysid.greybox_fit(duffing, u, y, ts=TS, evaluator="cc")
    with pytest.raises(hysid.ConfigError, match="evaluator"):
        hysid.greybox_fit(duffing, u, y, ts=TS, evaluator="fast")  # type: ignore[arg-type]
    with pytest.raises(hysid.ConfigError, match="equation model"):
        hysid.greybox_fit("bouc-wen", u, y, ts=TS, evaluator="tape")
