# Two commands a newcomer needs (see README):
#   make demo   - the main job: Step 3 (simulation, demo joystick, viewer) in two meshcat pages
#   make test   - the whole test suite: library, cross-process, launch, browser, and the notebooks (nbval)
# Both create the virtual environment .venv on first use and reuse it after.
# More: make test-fast (the unit tier, under a minute: the inner loop), make lint (ruff check and format, and lint-imports: the layers),
#       make notebooks (JupyterLab on notebooks/), make hub (a class's JupyterHub on 127.0.0.1:8000, course/), make book (the Jupyter Book, warnings are errors),
#       make bench (the benchmark suite; not part of make test; its plots go beside its results),
#       make bench-figures (the last make bench's plots into the book: the only way they change),
#       make mutate (mutation testing of the lessons, the library's core and every exercise's check: hours),
#       make mutate-seal (the same for the grading kernel's seal, in a worktree of its own: ten hours or more, SAMPLE=N),
#       make fuzz (the property-based tests with 100 times the examples, random ones: several minutes),
#       make test-lab (every notebook's Run All in JupyterLab, in a real browser: make test does 01; and a live
#       view in Notebook 7 and in JupyterLab as Colab runs it),
#       make test-more (the cases make test leaves out, each of a kind it keeps one of: about 7 min),
#       make test-hub (the hub with learners as Unix users: slow),
#       make test-robots (the Step 3 monitor on every robot of example-robot-data; the UR5, SO-100 and Go2 in Chromium),
#       make image (the learner image, podman), make hub-containers (the class on containers), make test-containers,
#       make assignments (the class's nbgrader assignments from the notebooks, into course/),
#       make grade (collect, autograde, feedback and course/grades.csv), make test-grade (every assignment graded),
#       make export (write the controllers from the notebooks that build them),
#       make run-notebooks (run every notebook and save its outputs, the ones nbval checks),
#       make lock (uv.lock anew: the newest versions pyproject.toml allows), make test-latest (make test against
#       those newest versions, in .venv-latest, without touching uv.lock: an upgrade is one command and one run).

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python

.PHONY: image hub-containers test-containers demo test test-fast test-more test-lab test-hub test-robots test-grade mutate mutate-seal assignments grade test-latest fuzz lint lock hub notebooks book bench bench-figures export run-notebooks venv clean

UV_VERSION := 0.13.9

# Exactly the versions in uv.lock (with their hashes), the ones the tests passed with: uv, from PyPI, installs
# the lock into .venv; --locked fails when uv.lock no longer matches pyproject.toml.  --inexact: uv must not
# remove what it did not install itself, since the ROS 2 wheels carry the metadata of the ROS packages inside
# them (ros-jazzy-rclpy brings "rclpy"), and removing those deletes rclpy's files.  --compile-bytecode: the
# install compiles every module once (uv does not by default), so a learner's first kernel, and every process
# of a first make test, does not compile mujoco, rclpy and Jupyter's modules as it imports them.
$(VENV)/.installed: pyproject.toml uv.lock Makefile  # Makefile: its set-up steps below change too
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check uv==$(UV_VERSION)
	$(VENV)/bin/uv sync --locked --inexact --all-extras --compile-bytecode --python $(PY) --quiet
	# The Jupyter server extension tutorial.view.widget.nodelay: enabled by a file a pip install puts in the
	# environment (pyproject.toml's data-files), and an editable install leaves out.
	$(PY) -m tutorial.view.widget.nodelay > /dev/null
	# nbgrader's Validate button reports "Success!" on a lesson notebook whatever its answers (no graded cells;
	# its check cells are the test): left out of this environment's JupyterLab (nbgrader validate still runs).
	$(VENV)/bin/jupyter labextension disable @jupyter/nbgrader:validate-assignment > /dev/null 2>&1
	touch $@

venv: $(VENV)/.installed

demo: $(VENV)/.installed
	$(PY) launch_py/step3_launch.py --demo

# Every tier (tests/conftest.py lists them), the notebooks under nbval, after the lint gate.
test: $(VENV)/.installed lint course/node_modules/.installed
	bash scripts/ensure-chromium.sh
	bash scripts/ensure-nftables.sh
	RTT_TEST_MODE=1 $(PY) -m pytest tests notebooks -m "not slow and not more" --durations=15 --nbval --nbval-sanitize-with notebooks/nbval_sanitize.cfg

# The hub's slow tests: two learners as two Unix users of this machine (root; Debian's python3), each with their
# own robots; and two learners in one ROS domain, each in a network namespace of their own (containers, pods).
# make test runs the hub with two learners under one user, each in their own domain.
test-hub: $(VENV)/.installed course/node_modules/.installed
	bash scripts/ensure-nftables.sh
	RTT_TEST_MODE=1 $(PY) -m pytest tests/test_hub.py -m slow -q

# Grading every assignment's fake submissions, the cheats of assignment 01 and a rebound check in each other
# (make test grades notebook 01's, one cheat among them), and every mistake only hidden cases catch under five
# learners' seeds: about 33 minutes; as root, in the grading sandbox.
test-grade: $(VENV)/.installed
	RTT_TEST_MODE=1 $(PY) -m pytest tests/test_grading.py tests/test_exercises.py -m slow -q

# The learner image (course/containers/Containerfile) with podman, as root: the base image is made first if
# missing (scripts/ensure-podman.sh); the host's uv cache and CA bundle are lent to the build.
IMAGE := localhost/ros-tank-tutorial:learner
export CONTAINERS_CONF := $(CURDIR)/course/containers/containers.conf
image:
	bash scripts/ensure-podman.sh
	podman build --quiet --file course/containers/Containerfile --tag $(IMAGE) \
	  --volume $(shell $(VENV)/bin/uv cache dir 2>/dev/null || echo $(HOME)/.cache/uv):/root/.cache/uv \
	  --volume /etc/ssl/certs/ca-certificates.crt:/run/host-ca.crt:ro --build-arg CA_BUNDLE=/run/host-ca.crt .

# The learner image and the class on containers (tests/test_containers.py), as root: about 4 minutes warm.
test-containers: $(VENV)/.installed course/node_modules/.installed
	bash scripts/ensure-podman.sh
	bash scripts/ensure-chromium.sh
	RTT_TEST_MODE=1 $(PY) -m pytest tests/test_containers.py -m slow -q -s

# The class's JupyterHub with each learner's server a container of that image (DockerSpawner, podman's API).
hub-containers: $(VENV)/.installed course/node_modules/.installed image
	bash scripts/hub-containers.sh

# The class's nbgrader course (course/): an assignment from each notebook with exercises, then its release.
assignments: $(VENV)/.installed
	PATH="$(CURDIR)/$(VENV)/bin:$$PATH" $(PY) course/assignments.py

# Collect the submissions from the exchange, autograde them, write and release feedback, and course/grades.csv.
# As root: each submission in the grading sandbox, sealed (book/course.md); its flags in grades.csv.
# ARGS go to course/grade.py: make grade ARGS="01_step1_tank_controller --jobs 2" (or --unsandboxed, not root).
grade: $(VENV)/.installed
	PATH="$(CURDIR)/$(VENV)/bin:$$PATH" $(PY) course/grade.py $(ARGS)

# Mutation testing (mutmut, configured in pyproject.toml) of the modules the notebooks build and the core they
# stand on: each mutant is a small change to one function, run against the tests that call it; the report says
# how many the tests caught and lists every survivor, with why it cannot be caught or that a test is missing.
# Hours here (every exercise's check with it).  mutmut keeps its results in mutants/ and re-tests only
# functions whose code changed:
# after adding tests, rm -rf mutants for a full run.
mutate: $(VENV)/.installed
	RTT_TEST_MODE=1 $(VENV)/bin/mutmut run
	$(PY) scripts/mutation_report.py

# The grading kernel's seal, which make mutate cannot reach (its tests run it in a Python of its own), in a git
# worktree beside this one (scripts/mutate_seal.py says how): about eleven hours for its 1,092 mutants; SAMPLE=N runs
# N of them drawn at random.
mutate-seal: $(VENV)/.installed
	$(PY) scripts/mutate_seal.py $(if $(SAMPLE),--sample $(SAMPLE))

# The cases make test leaves out to stay under 10 minutes, each of a kind make test keeps one real case of
# (marked "more": two more faults, two more network set-ups, one more robot across processes, and the mistakes
# only the exercises' hidden cases catch past the first of each exercise, and more): about 7 minutes.
test-more: $(VENV)/.installed
	bash scripts/ensure-nftables.sh
	RTT_TEST_MODE=1 $(PY) -m pytest tests -m more -q

# The unit tier only: no ROS, no process, no browser.
test-fast: $(VENV)/.installed
	RTT_TEST_MODE=1 $(PY) -m pytest tests -m unit -q

# The Step 3 monitor on all 68 robots of example-robot-data that urdfdom accepts (make test keeps 3), and the UR5's,
# SO-100's and Go2's pictures in Chromium (make test draws the Panda's): about 2.5 min, the meshes converted cold.
test-robots: $(VENV)/.installed
	bash scripts/ensure-chromium.sh
	bash scripts/ensure-debian-package.sh check_urdf liburdfdom-tools "make test-robots (urdfdom's check_urdf)"
	RTT_TEST_MODE=1 $(PY) -m pytest tests/test_any_robot.py -m slow -q

# Every notebook's Run All in JupyterLab, as a learner runs it (tests/test_jupyterlab.py; make test runs the
# setup check and the two notebooks a learner works in with the mouse, and nbval runs every notebook).
test-lab: $(VENV)/.installed
	bash scripts/ensure-chromium.sh
	RTT_LAB_ALL=1 $(PY) -m pytest tests/test_jupyterlab.py tests/test_frontends.py -q

# The property-based tests (hypothesis) of tests/test_fuzz_*.py at length: random examples, 100 times as
# many as make test's fixed set (RTT_FUZZ_FACTOR=N changes that); failures are kept in .hypothesis/ and
# tried first next time (tests/fuzzing.py).
fuzz: $(VENV)/.installed
	RTT_FUZZ=1 RTT_TEST_MODE=1 $(PY) -m pytest tests/test_fuzz_files.py tests/test_fuzz_messages.py tests/test_meshcat_server.py -m unit -q

# ruff, then the library's layers (import-linter's contracts in pyproject.toml; tests/test_layers.py proves them)
lint: $(VENV)/.installed
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .
	$(VENV)/bin/lint-imports --no-logo

# The notebooks carry recorded 3D views (scripts in their outputs): trusting the project's own
# notebooks lets JupyterLab show them; an untrusted notebook shows those outputs empty.
# JupyterLab on the clone, opening notebook 00; its terminals start in the clone with the rtt-* programs on their
# PATH (a shell that is not a login shell keeps it), so the notebooks' "Outside Jupyter" commands run as written.
# As root (a container, a lab's VM) JupyterLab wants --allow-root.  jupyter-config/learner leaves nbgrader out
# (its menu, panels and server parts are the teacher's and the class's: make assignments, make grade, make hub).
notebooks: $(VENV)/.installed
	$(VENV)/bin/jupyter trust notebooks/[0-9][0-9]_*.ipynb
	PATH="$(CURDIR)/$(VENV)/bin:$$PATH" JUPYTER_CONFIG_PATH="$(CURDIR)/jupyter-config/learner" $(VENV)/bin/jupyter lab --ip=127.0.0.1 --ServerApp.root_dir=. \
		--LabApp.default_url=/lab/tree/notebooks/00_setup_check.ipynb \
		--ServerApp.terminado_settings=shell_command=/bin/bash $(if $(filter 0,$(shell id -u)),--allow-root)

export: $(VENV)/.installed
	$(PY) scripts/export_notebooks.py

run-notebooks: $(VENV)/.installed
	$(PY) scripts/run_notebooks.py

book: $(VENV)/.installed
	$(VENV)/bin/jupyter-book build book --warningiserror --keep-going

# The browser experiment needs Chromium, the cross-host one nftables (it skips, saying why, when not root).
bench: $(VENV)/.installed
	bash scripts/ensure-chromium.sh
	bash scripts/ensure-nftables.sh
	$(PY) -m benchmarks.run

# The book's benchmark plots from the last make bench (benchmarks/results/): the only way they change.
bench-figures: $(VENV)/.installed
	$(PY) -m benchmarks.publish

# A class's JupyterHub on this machine, for a trial: http://127.0.0.1:8000, learners learner1..learner3,
# password tanktutorial (course/jupyterhub_config.py says how a course changes each).  The proxy comes from npm.
hub: $(VENV)/.installed course/node_modules/.installed
	$(VENV)/bin/jupyterhub -f course/jupyterhub_config.py

course/node_modules/.installed: course/package.json course/package-lock.json
	cd course && npm ci --no-audit --no-fund --silent
	touch $@

# The lock anew, every package at the newest version pyproject.toml allows (then make test, and commit uv.lock).
lock: $(VENV)/.installed
	$(VENV)/bin/uv lock --upgrade

# make test in a second environment with the newest versions pyproject.toml allows, the lock untouched;
# it first prints every package whose version differs from uv.lock.
test-latest: $(VENV)/.installed
	rm -rf .venv-latest
	$(PYTHON) -m venv .venv-latest
	.venv-latest/bin/pip install --quiet --disable-pip-version-check uv==$(UV_VERSION)
	.venv-latest/bin/uv pip install --python .venv-latest/bin/python --quiet --upgrade -e ".[notebook,test,book,bench]"
	$(PY) scripts/lock_diff.py .venv-latest/bin/python
	touch .venv-latest/.installed
	$(MAKE) test VENV=.venv-latest

clean:
	rm -rf $(VENV) .venv-latest .pytest_cache book/_build
