"""Both front ends take the same knobs: every classifier knob Python's
``classifier_options`` takes is a flag of ``neurotex train``, and every flag the CLI's help
gives to a classifier (``With `--classifier KIND```) is a knob Python takes; the network's
defaults are the CLI's."""

import re

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


def test_the_network_knobs_reach_training_with_the_cli_defaults():
    defaults = _native.snn_defaults()
    assert set(defaults) == set(_native.classifier_knobs("snn"))
    help_text = run_cli("train", "--help").stdout
    for knob in ("hidden", "tau_syn_ms", "tau_mem_ms", "tau_out_ms"):
        text = help_text.split(flag("snn", knob), 1)[1].split("\n  -", 1)[0]
        shown = re.search(r"\[default: ([0-9.]+)", text).group(1)
        assert float(shown) == float(defaults[knob]), knob


def test_a_broken_knob_is_named_as_python_spells_it(sim):
    with pytest.raises(neurotex.ParameterError, match=r"invalid parameter `hidden`"):
        neurotex.Model.train(sim, classifier="snn", classifier_options={"hidden": 0})
    with pytest.raises(neurotex.ParameterError, match=r"invalid parameter `tau_mem_ms`"):
        neurotex.SpikingModel.train(sim, tau_mem_ms=-1.0)


def test_a_knob_the_network_does_not_take_is_named_with_the_networks_knobs(sim):
    with pytest.raises(neurotex.ParameterError, match=r"`trees` for the spiking network; its options are hidden"):
        neurotex.Model.train(sim, classifier="snn", classifier_options={"trees": 3})
