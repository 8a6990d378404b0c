# Two commands a newcomer needs (see README):
#   make demo   - the main job: Step 3 (simulation, demo joystick, viewer) in two meshcat pages
#   make test   - the whole test suite
# Both create the virtual environment .venv on first use and reuse it after.

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python

.PHONY: demo test venv clean

$(VENV)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check -e ".[test]"
	touch $@

venv: $(VENV)/.installed

demo: $(VENV)/.installed
	$(PY) launch_py/step3_launch.py --demo

test: $(VENV)/.installed
	bash scripts/ensure-chromium.sh
	$(PY) -m pytest

clean:
	rm -rf $(VENV) .pytest_cache book/_build
