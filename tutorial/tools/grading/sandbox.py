"""Grading in a sandbox: each submission's kernel as a user of its own, without network, limited, sealed.

``course/grade.py`` gives each grading job a Unix user of its own and sets
``RTT_SANDBOX`` (:class:`Job`, as JSON) for ``nbgrader autograde``; the
course's ``nbgrader_config.py`` then executes notebooks with
:class:`SandboxedExecute`, whose :class:`SandboxedKernelManager` starts the
kernel:

* in a network namespace of its own (loopback only: ROS 2 still runs inside,
  nothing leaves it) and a mount namespace of its own, where the course
  folder, the repository's teacher-only folders (``notebooks``, ``course``,
  ``book``, ``.git``), ``/home``, ``/root`` (but the Python installation)
  and ``/srv`` are empty, ``/tmp``, ``/var/tmp`` and ``/dev/shm`` are the
  kernel's own, and every other mount is read-only (``/run/lock`` too); the
  kernel keyrings (the user ID's, past any process) refused to it and every
  process it starts, by the kernel itself before any answer runs
  (:mod:`tutorial.tools.grading.keyrings`);
* as the job's user, with no privileges (``setpriv --no-new-privs``), in a
  working folder of its own (a copy of the submission's folder), with a
  scrubbed environment (no ``NBGRADER_EXECUTION``);
* under limits: address space (a ``MemoryError`` in the cell), processes
  and threads (``RLIMIT_NPROC``, per user), CPU seconds, and, where root
  can write cgroup v1, a memory and a pids cgroup as a backstop;
* sealed (:mod:`tutorial.tools.grading.seal`): the grader reads the seal's
  signed verdicts from a pipe and writes the good ones to the job's
  verdict file, which ``course/grade.py`` turns into grades and flags.

The kernel talks to nbgrader over Unix sockets (ZeroMQ's ``ipc``), which
cross the network namespace.  Needs root (Linux: ``unshare``, ``setpriv``,
``prlimit``, ``ip`` from util-linux and iproute2).  The manager runs in
nbgrader's process, on its event loop's thread; its pipe reader on a thread of its own.

The module is over 400 lines and still one job: how nbgrader runs a submission's kernel in this course (the
sandboxed kernel, its executor, and :class:`RefusedExecute`, the refusal to run one any other way).
"""

from __future__ import annotations

import asyncio
import dataclasses
import hashlib
import json
import os
import secrets
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import threading
from pathlib import Path

from jupyter_client.manager import AsyncKernelManager
from nbconvert.preprocessors import Preprocessor
from nbgrader.preprocessors import Execute

from tutorial.tools.grading import judged
from tutorial.tools.grading.judge import genuine, signed

ENV = "RTT_SANDBOX"
PRIVATE = ("/tmp", "/var/tmp", "/dev/shm")  # the kernel's own, empty at its start
PASSED_ENV = ("PATH", "LANG", "LC_ALL", "ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE", "RTT_TEST_MODE", "MUJOCO_GL")


@dataclasses.dataclass
class Job:
    """One grading job's sandbox (``RTT_SANDBOX``, as JSON).

    Attributes:
        user, uid, gid: the job's Unix user.
        folder: the job's folder (root's, 0711): each kernel gets a subfolder.
        verdicts: the file the seal's checked verdicts are appended to (the grader's alone).
        hide: folders the kernel sees empty (the course, the teacher's notebooks, ...).
        test_calls: each test cell's statement (``check_x(answer).require()``): the seal's only callers of require().
        checks: the modules the test cells import their checks from: what the seal snapshots.
        seed: the learner's seed of hidden cases (from the teacher's, ``course/grade.py``).
        judge_key: the key (hex) the judge signs its lines with: the grader's, never the kernel's.
        memory_bytes: the address space a kernel may have (RLIMIT_AS): past it, a ``MemoryError``.
        processes: processes and threads the job's user may have (RLIMIT_NPROC).
        cpu_seconds: CPU time a kernel may use (RLIMIT_CPU).
        cgroup_memory_bytes: the memory cgroup's limit (resident memory, a backstop); 0: none.
    """

    user: str
    uid: int
    gid: int
    folder: str
    verdicts: str
    hide: list[str]
    test_calls: list[str]
    checks: list[str] = dataclasses.field(default_factory=list)
    seed: str = ""
    judge_key: str = ""
    memory_bytes: int = 4 << 30
    processes: int = 256
    cpu_seconds: int = 600
    cgroup_memory_bytes: int = 3 << 30

    @classmethod
    def from_env(cls) -> Job | None:
        text = os.environ.get(ENV)
        return cls(**json.loads(text)) if text else None

    def to_env(self) -> str:
        return json.dumps(dataclasses.asdict(self))


def sealed_seed(seed: str) -> str:
    """The seed of the sealed checks' hidden cases, from the learner's: the kernel holds it (where an answer
    that reads the kernel's memory finds it), and the judge's draws, from ``seed`` itself, cannot be had from it.
    Empty for an empty seed (no hidden cases)."""
    return hashlib.sha256(f"{seed}/sealed".encode()).hexdigest()[:16] if seed else ""


def cgroups(job: Job) -> list[Path]:
    """The job's memory and pids cgroups (cgroup v1), made with their limits; none where they cannot be
    (no cgroup v1, not root: the rlimits alone then bound the kernel).  Never raises; any thread."""
    made = []
    for controller, settings in (
        ("memory", {"memory.limit_in_bytes": job.cgroup_memory_bytes}),
        ("pids", {"pids.max": job.processes}),
    ):
        base = Path("/sys/fs/cgroup") / controller
        if not (base / "cgroup.procs").exists() or not os.access(base, os.W_OK):
            continue
        group = base / f"rtt-grade-{job.user}"
        try:
            group.mkdir(exist_ok=True)
            for name, value in settings.items():
                if value:
                    (group / name).write_text(str(value))
        except OSError:
            continue
        made.append(group)
    return made


def sandbox_command(job: Job, kernel: list[str], keep: list[str], groups: list[Path] = ()) -> list[str]:
    """``kernel`` wrapped: namespaces, hidden folders (``keep`` bound back), the cgroups ``groups``, the job's
    user and limits: the command to run as root (a list for ``subprocess``; every path shell-quoted).

    Pure: it makes nothing; any thread.  The command fails (exit status 1, unshare's or mount's message on
    stderr) where namespaces cannot be made."""
    script = [
        "set -e",
        "ip link set lo up",
        "mount --make-rprivate /",
    ]
    q = shlex.quote
    held = Path(job.folder) / ".keep"
    for k, path in enumerate(keep):
        script += [f"mkdir -p {q(f'{held}/{k}')}", f"mount --bind {q(path)} {q(f'{held}/{k}')}"]
    for path in job.hide:
        script.append(f"if [ -d {q(path)} ]; then mount -t tmpfs -o mode=755,size=1m tmpfs {q(path)}; fi")
    for path in PRIVATE:
        script.append(f"mount -t tmpfs -o mode=1777,size=2g tmpfs {path}")
    # POSIX message queues: the new IPC namespace's own (the host's mount, 1777, would outlast the kernel)
    script.append("if [ -d /dev/mqueue ]; then mount -t mqueue mqueue /dev/mqueue; fi")
    for k, path in enumerate(keep):  # a clone under /tmp keeps its library and environment
        script += [f"mkdir -p {q(path)}", f"mount --move {q(f'{held}/{k}')} {q(path)}"]
    # Last, every other mount read-only, world-writable folders such as /run/lock included (a note left there
    # would reach the next submission): the job's folder (its kernels' working folders, the user's alone) and
    # the private folders stay writable; /proc, /sys and /dev are the kernel's own or root's.  A mount that
    # cannot be made read-only stops the kernel (fail closed).
    folder = os.path.realpath(job.folder)  # as mountinfo names it
    script.append(f"mount --bind {q(folder)} {q(folder)}")
    skipped = "|".join(q(p) for p in (folder, *PRIVATE))
    script += [
        "set -f",  # the mount points below are words, never patterns
        "for mp in $(cut -d' ' -f5 /proc/self/mountinfo); do",
        # mountinfo writes a space as \040: %b reads an octal escape as \0NNN
        "  mp=$(printf '%b' \"$(printf '%s' \"$mp\" | sed 's/\\\\\\([0-7][0-7][0-7]\\)/\\\\0\\1/g')\")",
        f'  case "$mp" in /proc|/proc/*|/sys|/sys/*|/dev|/dev/*|{skipped}) continue;; esac',
        '  mountpoint -q "$mp" || continue',  # a mount hidden under another (a hidden folder under /tmp)
        '  mount -o remount,bind,ro "$mp"',
        "done",
    ]
    for group in groups:
        script.append(f"echo $$ > {q(str(group / 'cgroup.procs'))}")
    script.append('exec "$@"')
    return [
        "unshare",
        "--mount",
        "--net",
        "--ipc",
        "--",
        "/bin/sh",
        "-c",
        "\n".join(script),
        "sandbox",
        "setpriv",
        f"--reuid={job.uid}",
        f"--regid={job.gid}",
        "--clear-groups",
        "--no-new-privs",
        "--",
        "prlimit",
        f"--as={job.memory_bytes}",
        f"--nproc={job.processes}",
        f"--cpu={job.cpu_seconds}:{job.cpu_seconds + 5}",  # SIGXCPU, then SIGKILL 5 s later (said apart)
        "--core=0",
        "--",
        *kernel,
    ]


def kept_paths(hide: list[str]) -> list[str]:
    """What a hidden or private folder holds that the kernel needs: the Python installation (root's pyenv,
    say), the environment, and the library's own folders of a clone in a home folder or under /tmp (never its
    notebooks or course)."""
    repository = Path(__file__).resolve().parents[3]  # tutorial/tools/grading/sandbox.py
    needed = {os.path.realpath(sys.base_prefix), os.path.realpath(sys.prefix)}
    needed |= {str(repository / p) for p in ("tutorial", "project", "model") if (repository / p).is_dir()}
    keep = []
    for path in needed:
        if any(path.startswith(h.rstrip("/") + "/") for h in [*hide, *PRIVATE]):
            keep.append(path)
    return sorted(keep)


class SandboxedKernelManager(AsyncKernelManager):
    """A kernel started in the job's sandbox (:func:`sandbox_command`), sealed, over Unix sockets."""

    async def _async_pre_start_kernel(self, **kw):
        job = Job.from_env()
        if job is None:
            raise RuntimeError(f"{ENV} is not set: grade with course/grade.py, which sets up the sandbox")
        self._job = job
        here = Path(job.folder) / secrets.token_hex(6)
        work, ipc = here / "work", here / "ipc"
        source = Path(kw.get("cwd") or os.getcwd())
        # links copied as links (root must not follow a submission's link), then given to the job's user
        shutil.copytree(source, work, symlinks=True, ignore=shutil.ignore_patterns(".ipynb_checkpoints"))
        ipc.mkdir()
        for path in (here, work, ipc, *work.rglob("*")):
            os.lchown(path, job.uid, job.gid)
        os.chmod(here, 0o700)
        self.transport = "ipc"
        self.ip = str(ipc / "kernel")
        self.connection_file = str(here / "connection.json")
        kw["cwd"] = str(work)
        kw["env"] = {k: v for k, v in (kw.get("env") or os.environ).items() if k in PASSED_ENV}
        kw["env"].update(HOME=str(work), PYTHONDONTWRITEBYTECODE="1")
        cmd, kw = await super()._async_pre_start_kernel(**kw)
        os.chown(self.connection_file, job.uid, job.gid)
        self._key = secrets.token_bytes(32)
        self._key_read, self._key_write = os.pipe()
        self._verdict_read, self._verdict_write = os.pipe()
        self._judges_end, self._kernels_end = socket.socketpair()  # the judge's checks, data only (judge.py)
        kw["pass_fds"] = (self._key_read, self._verdict_write, self._kernels_end.fileno())
        kw["env"]["RTT_SEAL_FDS"] = f"{self._key_read},{self._verdict_write}"
        kw["env"][judged.ENV] = str(self._kernels_end.fileno())
        judges = Path(job.folder) / (here.name + "-judge")  # root's: rclpy writes its log there, as root
        judges.mkdir(mode=0o700)
        self._judge_env = {k: v for k, v in kw["env"].items() if k in PASSED_ENV} | {"HOME": str(judges)}
        # ipykernel's own launcher's arguments (the connection file, nbgrader's history in memory), sealed first
        kernel = [sys.executable, "-I", "-m", "tutorial.tools.grading.sealed_kernel", *cmd[cmd.index("-f") :]]
        return sandbox_command(job, kernel, kept_paths(job.hide), cgroups(job)), kw

    async def _async_launch_kernel(self, kernel_cmd, **kw):
        try:
            await super()._async_launch_kernel(kernel_cmd, **kw)
        finally:
            os.close(self._key_read)
            # the grader's own end, for the cells' marks (:meth:`mark_cell`), closed before the reader's join
            self._marks = os.dup(self._verdict_write)
            os.close(self._verdict_write)
            self._kernels_end.close()
        job = self._job
        self._start_judge(job)
        given = {
            "key": self._key.hex(),
            "test_calls": job.test_calls,
            "hidden": job.hide,
            "checks": job.checks,
            "seed": sealed_seed(job.seed),
        }
        with os.fdopen(self._key_write, "w") as out:
            json.dump(given, out)
        self._reader = threading.Thread(target=self._read_verdicts, name="seal-verdicts", daemon=True)
        self._reader.start()

    def _start_judge(self, job: Job) -> None:
        """The judge (:mod:`tutorial.tools.grading.judge`) of this kernel's judged checks: the grader's process,
        outside the sandbox, which imports the teacher's checks now and gets the seed on a pipe."""
        fd = self._judges_end.fileno()
        command = ["prlimit", f"--as={job.memory_bytes}", f"--cpu={job.cpu_seconds}", "--core=0", "--"]  # the kernel's
        command += [sys.executable, "-I", "-m", "tutorial.tools.grading.judge", str(fd), job.verdicts]
        self._judge = subprocess.Popen(
            [*command, ",".join(job.checks)],
            pass_fds=(fd,),
            stdin=subprocess.PIPE,
            stderr=open(Path(self._judge_env["HOME"]) / "judge.log", "ab"),  # noqa: SIM115 - the child's
            env=self._judge_env,
            text=True,
        )
        self._judges_end.close()
        self._judge.stdin.write(job.seed + "\n" + job.judge_key + "\n")
        self._judge.stdin.close()

    async def _async_cleanup_resources(self, restart: bool = False):
        """After the kernel ended, shut down or dead (nbclient then only cleans up): every line it and its judge
        wrote is in the verdict file before nbgrader goes on."""
        await super()._async_cleanup_resources(restart=restart)
        marks, self._marks = getattr(self, "_marks", None), None
        if marks is not None:  # the pipe ends (and the reader with it) when the kernel's end and this one are closed
            os.close(marks)
        reader = getattr(self, "_reader", None)
        if reader is not None:
            await asyncio.get_running_loop().run_in_executor(None, reader.join, 10.0)
        judge = getattr(self, "_judge", None)
        if judge is not None:  # it ends when the kernel's end of the socket closes; a check still running, later
            try:
                await asyncio.get_running_loop().run_in_executor(None, judge.wait, 30.0)
            except subprocess.TimeoutExpired:
                judge.kill()
                judge.wait()

    # what nbclient calls (the base class binds its own function); shutdown_kernel calls the method above itself
    cleanup_resources = _async_cleanup_resources

    def mark_cell(self, index: int) -> None:
        """Say on the seal's pipe that cell ``index`` of the notebook starts: the seal's notes after it, which
        name no exercise, are the notes of that cell's exercise (``course/sandboxing.py``'s ``judge``).  The
        kernel's lines of the cell before are in the pipe already (the seal writes them before the cell ends), so
        the reader keeps their order.  nbgrader's event loop's thread, between cells."""
        if getattr(self, "_marks", None) is not None:
            os.write(self._marks, (signed(self._key, f"cell\t{index}") + "\n").encode())

    def _read_verdicts(self) -> None:
        """The seal's pipe, line by line, to the job's verdict file (its reader thread, until the pipe closes).

        A signed line goes as it is, without its signature; any other (bytes an answer wrote on the pipe) as
        a note of tampering.
        """
        fd = os.open(self._job.verdicts, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o600)
        with os.fdopen(self._verdict_read, "rb") as pipe, os.fdopen(fd, "a", encoding="utf-8") as out:
            refused = written = 0
            while raw := pipe.readline(MAX_SEAL_LINE):  # a line past the limit is read, and refused, in pieces
                line = raw.decode("utf-8", "replace").removesuffix("\n")
                body = genuine(self._key, line)  # signed as the judge signs, with the seal's key
                # a signed body with a line break of any kind (str.splitlines()'s), or naming the judge, is no seal's
                ok = body is not None and raw.endswith(b"\n") and len(body.splitlines()) <= 1 and "judged" not in body
                written += ok
                if ok and written <= MAX_SEAL_LINES:
                    out.write(body + "\n")
                elif refused < MAX_REFUSED_LINES:  # counted, not written without end
                    out.write("note\ttampering\tan unsigned line on the seal's pipe\t\n")
                refused += not ok
                out.flush()


MAX_SEAL_LINE = 4096  # bytes of one of the seal's lines (its longest, a verdict's reasons, is far shorter)
MAX_REFUSED_LINES = 20  # tampering notes written for the bytes an answer writes on the seal's pipe
MAX_SEAL_LINES = 10_000  # signed lines written (a notebook's checks and notes make tens; the key is in the kernel)

KERNEL_DIED = "the kernel died while this cell ran"
CPU_TIME_RAN_OUT = "its CPU time ran out"  # RLIMIT_CPU's SIGXCPU
NOT_RUN = "not run: the kernel died in an earlier cell"
# What became of the kernel in a cell, in the cell's metadata: written by SandboxedExecute alone (a kernel writes
# outputs, never a cell's metadata; a submission's own is taken off first), read by course/sandboxing.py's judge.
KERNEL_MARK = "rtt_grading_kernel"
DIED, OUT_OF_CPU_TIME, NOT_RUN_MARK = "died", "out of CPU time", "not run"


UNSANDBOXED = "RTT_UNSANDBOXED"  # "1": course/grade.py --unsandboxed, the teacher's own choice (not for a class)
REFUSED = (
    "this course grades learners' code only in its sandbox: run `make grade` (course/grade.py), which starts "
    'nbgrader autograde there (one learner: `make grade ARGS="--student NAME"`), or `make grade '
    "ARGS=--unsandboxed` to run submissions with your own rights on purpose (not for a class). Plain "
    "`nbgrader autograde` would run every answer as you, unsealed."
)


class RefusedExecute(Preprocessor):
    """``nbgrader autograde`` started by hand (or by the formgrader's button): it runs no learner's code.

    The course's ``nbgrader_config.py`` puts it in place of nbgrader's preprocessors unless
    ``course/grade.py`` started the run (:data:`ENV` or :data:`UNSANDBOXED`), so a teacher regrading one
    learner with nbgrader's own command gets a refusal that says what to run, not a grade computed with the
    teacher's rights by the answer's own code.

    Raises:
        RuntimeError: always (:data:`REFUSED`); nbgrader names the notebook and grades nothing of it.
    """

    def __call__(self, nb, resources):  # a Preprocessor not enabled would pass the notebook on: this one never does
        raise RuntimeError(REFUSED)


class SandboxedExecute(Execute):
    """nbgrader's Execute, with each kernel in the sandbox (:class:`SandboxedKernelManager`).

    A kernel that dies (an answer that kills it, a crash in a library) ends the run, not the grading of the
    submission: the cell that was running gets an error (``DeadKernelError``, :data:`KERNEL_DIED`, and
    :data:`CPU_TIME_RAN_OUT` where the CPU time limit stopped it), every
    code cell after it one that says it did not run (:data:`NOT_RUN`, so nbgrader gives its check no
    points: an empty check cell would pass), and the exercises before it keep what they earned.  Each of
    those cells also gets :data:`KERNEL_MARK` in its metadata (:data:`DIED`, :data:`OUT_OF_CPU_TIME` or
    :data:`NOT_RUN_MARK`), which the flags are read from: an answer can raise an error of any name and
    text, but it cannot write a cell's metadata.  nbgrader's event loop's thread.
    """

    def __init__(self, *args, **kwargs):
        kwargs["kernel_manager_class"] = SandboxedKernelManager
        super().__init__(*args, **kwargs)
        self._died = False

    def preprocess(self, nb, resources=None, km=None):
        self._died = False  # each notebook with a kernel of its own (one instance may run several)
        for cell in nb.cells:  # a mark the submission brought with it says nothing of this run
            cell.metadata.pop(KERNEL_MARK, None)
        return super().preprocess(nb, resources, km)

    def preprocess_cell(self, cell, resources, index):
        from nbclient.exceptions import DeadKernelError
        from nbformat.notebooknode import NotebookNode

        def error(text):
            return NotebookNode(output_type="error", ename="DeadKernelError", evalue=text, traceback=[text])

        if self._died:
            if cell.cell_type == "code":
                cell.outputs = [error(NOT_RUN)]
                cell.metadata[KERNEL_MARK] = NOT_RUN_MARK
            return cell, resources
        try:
            getattr(self.km, "mark_cell", lambda index: None)(index)  # the sandbox's manager (a test's has none)
            return super().preprocess_cell(cell, resources, index)
        except DeadKernelError:
            self._died = True
            process = getattr(getattr(self.km, "provisioner", None), "process", None)  # the kernel's own: prlimit,
            ended = process.poll() if process is not None else None  # setpriv and unshare exec it, none forks
            out_of_time = ended == -signal.SIGXCPU
            cell.outputs.append(error(KERNEL_DIED + (f" ({CPU_TIME_RAN_OUT})" if out_of_time else "")))
            cell.metadata[KERNEL_MARK] = OUT_OF_CPU_TIME if out_of_time else DIED
            return cell, resources
