"""Arguments are read strictly: a float where a count is meant, strings where samples are
meant and a missing file are errors that say so, never a silent reading; the stream objects
and comparisons print and compare usefully."""

import pickle

import hysid
import numpy as np
import pytest


def play_record(n: int = 600):
    u = np.sin(np.linspace(0.0, 8.0 * np.pi, n)) * np.linspace(0.3, 1.0, n)
    y, z = np.empty_like(u), 0.0
    for k, v in enumerate(u):  # a play of width 0.15 and a linear term
        z = min(max(z, v - 0.15), v + 0.15)
        y[k] = 0.4 * v + z
    return u, y


def test_a_float_count_of_thresholds_is_a_type_error_naming_the_forms():
    u, y = play_record()
    with pytest.raises(TypeError, match=r"thresholds=20.0: give a count .* or the thresholds themselves"):
        hysid.identify_operator(u, y, family="pi", thresholds=20.0)  # type: ignore[arg-type]
    # Both accepted forms work.
    assert hysid.identify_operator(u, y, family="pi", thresholds=20).fit_percent > 90
    assert hysid.identify_operator(u, y, family="pi", thresholds=[0.05, 0.1, 0.2, 0.4]).fit_percent > 90


@pytest.mark.parametrize(
    "bad",
    [["1.0", "2.0", "3.0"], np.array([True, False, True]), np.array([1 + 1j, 2, 3]), [object(), 1.0, 2.0]],
)
def test_non_numeric_samples_are_a_type_error(bad):
    with pytest.raises(TypeError, match="numeric array"):
        hysid.identify_operator(bad, [1.0, 2.0, 3.0], family="pi")


def test_too_few_samples_says_so():
    with pytest.raises(hysid.DataError, match="too few samples: 3 usable samples"):
        hysid.identify_operator([0.0, 1.0, 0.5], [0.0, 1.0, 0.7], family="pi")


def test_a_missing_model_file_is_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError) as e:
        hysid.load_model(tmp_path / "nope.json")
    assert e.value.filename == str(tmp_path / "nope.json")
    # Still the package's own error for an unreadable model file (earlier code catches it).
    assert isinstance(e.value, hysid.ModelFileError)


def test_stream_objects_print_what_they_are():
    u, y = play_record()
    m = hysid.identify_operator(u, y, family="pi", ts=0.001).model
    assert repr(m.stepper(ts=0.001)) == f"Stepper({m.kind}: 1 input(s), 1 output(s), ts=0.001 s)"
    c = m.compensator()
    c.run(np.full(10, 1e3))
    text = repr(c)
    assert text.startswith(f"Compensator({m.kind}: preview ") and "clipped" in text, text
    assert "object at 0x" not in repr(m.stepper()) + text


def test_a_comparison_equals_its_pickled_copy_and_not_another():
    u, y = play_record()
    c = hysid.compare(u, y, families=["pi", "backlash"])
    assert pickle.loads(pickle.dumps(c)) == c
    other = hysid.compare(u, 1.5 * y, families=["pi", "backlash"])
    assert other != c
