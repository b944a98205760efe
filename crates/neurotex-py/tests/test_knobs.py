"""Both front ends take the same knobs: every classifier knob Python's
``classifier_options`` takes is a flag of ``neurotex train``, and every flag the CLI's help
gives to a classifier (``With `--classifier KIND```) is a knob Python takes; the network's
defaults are the CLI's."""

import re

import numpy as np
import pytest

import neurotex
from neurotex import _native

from conftest import run_cli

# A knob's flag: `--` and the knob in kebab case, with these exceptions.
SPELLED = {("knn", "k"): "--k", ("knn", "standardize"): "--no-standardize",
           ("forest", "seed"): "--forest-seed"}


def flag(kind, knob):
    if (kind, knob) in SPELLED:
        return SPELLED[(kind, knob)]
    prefix = "--snn-" if kind == "snn" else "--"
    return prefix + knob.replace("_", "-")


def cli_knobs(help_text):
    """Each classifier's flags, read from the help: a flag whose text begins `With
    `--classifier KIND``."""
    found = {}
    for m in re.finditer(r"^\s+(?:-\w, )?(--[a-z-]+)[^\n]*\n\s+With `--classifier (\w+)`",
                         help_text, re.M):
        found.setdefault(m.group(2), set()).add(m.group(1))
    return found


@pytest.mark.parametrize("kind", ["knn", "forest", "linear", "snn"])
def test_python_and_the_cli_take_the_same_classifier_knobs(kind):
    help_text = run_cli("train", "--help").stdout
    python = {flag(kind, k) for k in _native.classifier_knobs(kind)}
    for f in python:
        assert re.search(rf"^\s+(-\w, )?{re.escape(f)}\b", help_text, re.M), f"{kind}: {f}"
    if kind != "knn":
        assert cli_knobs(help_text)[kind] <= python, kind


@pytest.mark.parametrize("kind", ["forest", "linear", "snn"])
def test_the_knobs_defaults_are_the_clis(kind):
    defaults = _native.classifier_defaults(kind)
    assert set(defaults) == set(_native.classifier_knobs(kind))
    help_text = run_cli("train", "--help").stdout
    for knob, value in defaults.items():
        if value is None or isinstance(value, bool) and kind == "snn":
            continue  # a rule in words, or a flag without a value
        entry = re.search(rf"^\s+{re.escape(flag(kind, knob))} <\w+>\n(.*?)(?=\n\s+-|\Z)",
                          help_text, re.M | re.S)
        assert entry, f"{kind}: {knob}"
        shown = re.search(r"\[default: ([^\]]+)\]", entry.group(1))
        assert shown, f"{kind}: {knob}"
        if isinstance(value, bool):
            assert shown.group(1) == str(value).lower(), knob
        elif isinstance(value, str):
            assert shown.group(1) == value, knob
        else:
            assert float(shown.group(1)) == float(value), knob


def test_the_estimators_defaults_are_the_librarys():
    from neurotex import sklearn as nsk
    import inspect
    for cls, kind in ((nsk.KNNClassifier, "knn"), (nsk.RandomForestClassifier, "forest"),
                      (nsk.LogisticRegression, "linear")):
        params = inspect.signature(cls.__init__).parameters
        for knob, value in _native.classifier_defaults(kind).items():
            assert params[knob].default == value, (kind, knob)


def test_a_broken_knob_is_named_as_python_spells_it(sim):
    with pytest.raises(neurotex.ParameterError, match=r"invalid parameter `hidden`"):
        neurotex.Model.train(sim, classifier="snn", classifier_options={"hidden": 0})
    with pytest.raises(neurotex.ParameterError, match=r"invalid parameter `tau_mem_ms`"):
        neurotex.SpikingModel.train(sim, tau_mem_ms=-1.0)


def test_a_knob_the_network_does_not_take_is_named_with_the_networks_knobs(sim):
    with pytest.raises(neurotex.ParameterError, match=r"`trees` for the spiking network; its options are hidden"):
        neurotex.Model.train(sim, classifier="snn", classifier_options={"trees": 3})


def test_a_capped_overshoot_keeps_the_spikes_under_rounding_level_changes():
    """The same wandering recording, and the same with each sample times 1 + u 1e-12:
    with the overshoot kept (the reference scheme) the spikes move; capped they stay."""
    rng = np.random.default_rng(0)
    x = np.clip(0.5 + np.cumsum(rng.uniform(-0.01, 0.01, (10_000, 4, 4)), axis=0), 0, 1)
    nudged = x * (1 + rng.uniform(-1, 1, x.shape) * 1e-12)
    assert (nudged != x).any()
    kept = [neurotex.encode(r) for r in (x, nudged)]
    capped = [neurotex.encode(r, overshoot="capped") for r in (x, nudged)]
    assert kept[0].sum() > 500
    assert (kept[0] != kept[1]).any()
    np.testing.assert_array_equal(capped[0], capped[1])
    with pytest.raises(neurotex.ParameterError, match="overshoot"):
        neurotex.encode(x, overshoot="clipped")
