# Two commands a newcomer needs (see README):
#   make demo   - the main job: Step 3 (simulation, demo joystick, viewer) in two meshcat pages
#   make test   - the whole test suite: library, cross-process, launch, browser, and the notebooks (nbval)
# Both create the virtual environment .venv on first use and reuse it after.
# More: make notebooks (JupyterLab on notebooks/), make book (the Jupyter Book, warnings are errors),
#       make bench (the benchmark suite; not part of make test).

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python

.PHONY: demo test notebooks book bench venv clean

$(VENV)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check -e ".[notebook,test,book,bench]"
	touch $@

venv: $(VENV)/.installed

demo: $(VENV)/.installed
	$(PY) launch_py/step3_launch.py --demo

test: $(VENV)/.installed
	bash scripts/ensure-chromium.sh
	RTT_TEST_MODE=1 $(PY) -m pytest tests notebooks --nbval --nbval-sanitize-with notebooks/nbval_sanitize.cfg

notebooks: $(VENV)/.installed
	$(VENV)/bin/jupyter lab notebooks/

book: $(VENV)/.installed
	ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST $(PY) book/make_snapshots.py
	$(VENV)/bin/jupyter-book build book --warningiserror --keep-going

bench: $(VENV)/.installed
	$(PY) -m benchmarks.run

clean:
	rm -rf $(VENV) .pytest_cache book/_build book/_static/snapshots
