"""Results are typed and honest: every report field a class needs is read once at
construction and checked, so a report missing one (or holding the wrong type) is a clear
ReportError, never a silent None; results print, pickle and tabulate."""

import copy
import json
import pickle

import hysid
import pytest
from test_zoo import _loop


@pytest.fixture(scope="module")
def pi_result():
    u, y = _loop(400)
    return hysid.identify_operator(u, y, family="pi", thresholds=4)


def _without(report, path):
    """A copy of ``report`` with the field at ``path`` (dotted) removed."""
    rep = copy.deepcopy(report)
    *parents, last = path.split(".")
    node = rep
    for key in parents:
        node = node[key]
    del node[last]
    return rep


@pytest.mark.parametrize(
    "path",
    [
        "command",
        "fit.fit_percent",
        "fit.rmse",
        "search.termination.message",
        "search.elapsed_s",
        "model.kind",
        "details",
    ],
)
def test_a_missing_field_is_a_clear_error(pi_result, path):
    with pytest.raises(hysid.ReportError, match=f"report.{path} is missing"):
        hysid.Result(_without(pi_result.report(), path))


def test_a_missing_parameter_field_names_the_parameter(pi_result):
    rep = pi_result.report()
    del rep["model"]["parameters"][2]["value"]
    with pytest.raises(hysid.ReportError, match=r"model.parameters\[2\].value is missing"):
        hysid.Result(rep)


def test_an_ill_typed_field_is_a_clear_error(pi_result):
    rep = pi_result.report()
    rep["fit"]["fit_percent"] = "99.9"
    with pytest.raises(hysid.ReportError, match=r"report.fit.fit_percent: expected a number, got str"):
        hysid.Result(rep)
    rep = pi_result.report()
    rep["search"]["termination"]["converged"] = None
    with pytest.raises(hysid.ReportError, match="converged: expected true or false, got null"):
        hysid.Result(rep)
    rep = pi_result.report()
    rep["schema"] = "hysid.report/0"
    with pytest.raises(hysid.ReportError, match="hysid.report/1"):
        hysid.Result(rep)
    assert issubclass(hysid.ReportError, (hysid.HysidError, ValueError))


def test_fields_keep_their_meaning(pi_result):
    rep = pi_result.report()
    assert pi_result.fit_percent == rep["fit"]["fit_percent"]
    assert pi_result.rmse == rep["fit"]["rmse"]
    assert pi_result.termination == rep["search"]["termination"]["message"]
    assert pi_result.converged is rep["search"]["termination"]["converged"]
    assert list(pi_result.parameters) == [p["name"] for p in rep["model"]["parameters"]]
    assert pi_result.model.kind == "operator" and pi_result.model.family == "pi"
    assert pi_result.command == "identify operator" and pi_result.uncertainty == rep["uncertainty"]["method"]


def test_fit_report_tabulates_parameters_with_sigma(pi_result):
    text = pi_result.fit_report()
    assert text.startswith("[[Fit: identify operator]]")
    assert f"{pi_result.fit_percent:.4f}" in text and pi_result.termination in text
    for name, p in pi_result.parameters.items():
        line = next(line for line in text.splitlines() if line.strip().startswith(name + ":"))
        if p.std is not None:
            assert f"+/- {p.std:.4g}" in line
        assert ("(fixed)" in line) == p.fixed


def test_repr_and_pickle(pi_result):
    assert repr(pi_result).startswith("Result(identify operator: a0=")
    back = pickle.loads(pickle.dumps(pi_result))
    assert back == pi_result and back.report() == pi_result.report()
    assert (back.data.u == pi_result.data.u).all() and back.data.ts == pi_result.data.ts


def test_model_checks_its_file(pi_result):
    file = pi_result.model.file
    broken = {k: v for k, v in file.items() if k != "parameters"}
    with pytest.raises(hysid.ReportError, match="model.parameters is missing"):
        hysid.Model(broken)
    json.dumps(file)  # the file stays the model file
