"""course/z2jh/config.yaml is a valid values file of the Zero to JupyterHub chart version it names (4.4.0),
checked against that version's own schema (course/z2jh/values.schema.json), and says what the learner image
and the class's limits need.  No Kubernetes runs here: this is what is tested instead (book/course.md)."""

from __future__ import annotations

import json

import jsonschema
import pytest
import yaml

from conftest import ROOT

pytestmark = pytest.mark.unit

Z2JH = ROOT / "course" / "z2jh"


def values() -> dict:
    return yaml.safe_load((Z2JH / "config.yaml").read_text())


def merged(defaults: dict, config: dict) -> dict:
    """``config`` over the chart's own defaults, as Helm merges them before it validates."""
    out = dict(defaults)
    for key, value in config.items():
        out[key] = (
            merged(defaults[key], value) if isinstance(value, dict) and isinstance(defaults.get(key), dict) else value
        )
    return out


def errors(config: dict) -> list[str]:
    """What the chart's schema finds wrong in ``config``, merged over the chart's defaults (chart-values.yaml)."""
    schema = json.loads((Z2JH / "values.schema.json").read_text())
    defaults = yaml.safe_load((Z2JH / "chart-values.yaml").read_text())
    validator = jsonschema.Draft7Validator(schema)
    return [f"{'/'.join(map(str, e.path))}: {e.message}" for e in validator.iter_errors(merged(defaults, config))]


def test_the_values_file_is_valid_for_its_chart_version():
    assert errors(values()) == []
    assert "chart 4.4.0" in (Z2JH / "config.yaml").read_text() and "4.4.0" in (Z2JH / "README.md").read_text()


def test_the_schema_catches_a_wrong_values_file():
    """The check can fail: a misspelt key and a wrong type are both refused."""
    wrong = values()
    wrong["singleuser"]["memory"]["limitt"] = "2G"
    wrong["cull"]["timeout"] = "an hour"
    found = errors(wrong)
    assert any("limitt" in e for e in found) and any(e.startswith("cull/timeout") for e in found), found


def test_the_learners_pods_have_the_class_limits_and_stay_apart():
    single = values()["singleuser"]
    assert single["memory"]["limit"] == "2G"  # as course/limits.py
    assert single["cpu"]["guarantee"] <= single["cpu"]["limit"] == 1.0
    assert single["extraEnv"]["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "LOCALHOST"
    assert single["networkPolicy"]["enabled"] and not single["networkPolicy"]["egressAllowRules"]["privateIPs"]
    assert single["uid"] == 1000 and single["storage"]["homeMountPath"] == "/home/jovyan"
    assert values()["cull"]["enabled"] and values()["cull"]["timeout"] == 3600
