"""``python -I -m tutorial.tools.grading.sealed_kernel -f CONNECTION_FILE``: an IPython kernel, sealed before it starts.

:class:`tutorial.tools.grading.sandbox.SandboxedKernelManager` starts it with
``RTT_SEAL_FDS=R,W``: the grader writes to ``R`` (JSON) the seal's key, the
test cells' statements, the folders it hides, the check modules and the
learner's seed of hidden cases, and reads the signed verdicts from ``W``; ``RTT_JUDGE_FD`` is its socket to the
judge, which runs the checks of :data:`tutorial.tools.grading.judge.JUDGED` (:mod:`tutorial.tools.grading.judged`).
``-I`` keeps the submission's folder off ``sys.path`` while the teacher's
modules are imported (a ``tutorial/`` folder there would otherwise shadow them).
"""

import ctypes
import json
import os

from tutorial.tools.grading import judged, keyrings, seal

PR_SET_DUMPABLE = 4  # Linux's prctl(2) option


def main() -> None:
    # Not dumpable: another process of the same user (a subprocess of an answer, which the seal does not
    # watch) can then neither ptrace this kernel nor read its memory (/proc/PID/mem), where the key lives.
    ctypes.CDLL(None).prctl(PR_SET_DUMPABLE, 0, 0, 0, 0)
    # The keyrings are the user ID's, not this process's: keyctl refused to this kernel and every process it
    # starts, so no answer leaves, reads or locks a key there (keyrings.py).
    keyrings.refuse()
    key_fd, verdict_fd = (int(fd) for fd in os.environ.pop("RTT_SEAL_FDS").split(","))
    with os.fdopen(key_fd, "rb") as pipe:
        given = json.loads(pipe.read())
    # Imported before the seal: the seal takes the code of ipykernel's own signal handler from it, as it was
    from ipykernel.kernelapp import launch_new_instance

    # The judged checks ask the judge, a process of the grader's, before the seal snapshots the checks' modules
    judge_fd = os.environ.pop(judged.ENV, None)  # the sandbox always gives one; without, the checks run here
    if judge_fd is not None:
        judged.install(int(judge_fd), given["checks"])

    seal.install(
        bytes.fromhex(given["key"]), verdict_fd, given["test_calls"], given["hidden"], given["checks"], given["seed"]
    )
    del given
    launch_new_instance()


if __name__ == "__main__":
    main()
