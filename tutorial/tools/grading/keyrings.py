"""The calling user's kernel keyrings, emptied: a note one graded submission leaves there never reaches the next.

Linux keeps a user's keyring (``@u``), user-session keyring (``@us``) and
persistent keyring by user ID, not by process: they outlive the processes
that wrote them (the persistent one for days).  Two submissions graded in
turn as one job's user could pass a key between them, and a user given the
same ID later would find it.  So the grading kernel empties them, and starts
a session keyring of its own, before any answer runs
(:mod:`tutorial.tools.grading.sealed_kernel`), and ``course/sandboxing.py``
empties them once more, as the job's user, when the job ends:

    python -I -m tutorial.tools.grading.keyrings

Python's standard library has no ``keyctl(2)``: it is called through ctypes
(the system call's number is x86_64's, the only machine the ROS 2 wheels
are built for).  Any thread.
"""

from __future__ import annotations

import ctypes
import errno
import os

SYS_KEYCTL = 250  # x86_64
KEYCTL_JOIN_SESSION_KEYRING = 1
KEYCTL_CLEAR = 7
KEYCTL_GET_PERSISTENT = 22
KEY_SPEC_SESSION_KEYRING = -3
KEY_SPEC_USER_KEYRING = -4
KEY_SPEC_USER_SESSION_KEYRING = -5
# Keys cannot be kept here at all: no keyrings in the kernel (ENOSYS), keyctl refused wholesale (EPERM: a
# container's seccomp profile), or no persistent keyrings (EOPNOTSUPP).  Nothing can be left, nothing to empty.
NOT_HERE = (errno.ENOSYS, errno.EPERM, errno.EOPNOTSUPP)

_libc = ctypes.CDLL(None, use_errno=True)  # this module's own: its syscall's result type is set below
_libc.syscall.restype = ctypes.c_long


def _keyctl(operation: int, *args) -> int:
    # syscall(2) reads every argument as a long: each passed as one (an int's upper half would be undefined)
    result = _libc.syscall(*(ctypes.c_long(a) for a in (SYS_KEYCTL, operation, *args)))
    if result < 0:
        code = ctypes.get_errno()
        raise OSError(code, f"keyctl({operation}): {os.strerror(code)}")
    return result


def clear() -> None:
    """A new, empty session keyring for this process; the user's keyring, user-session keyring and persistent
    keyring emptied.

    Raises:
        OSError: a keyring could not be emptied (not where keyrings cannot be kept at all: :data:`NOT_HERE`).
    """
    steps = [
        lambda: _keyctl(KEYCTL_JOIN_SESSION_KEYRING, 0),  # anonymous: not the grader's, inherited across setuid
        lambda: _keyctl(KEYCTL_CLEAR, KEY_SPEC_USER_KEYRING),
        lambda: _keyctl(KEYCTL_CLEAR, KEY_SPEC_USER_SESSION_KEYRING),
        # the persistent keyring, linked into the new session keyring to be found, then emptied
        lambda: _keyctl(KEYCTL_CLEAR, _keyctl(KEYCTL_GET_PERSISTENT, -1, KEY_SPEC_SESSION_KEYRING)),
    ]
    for step in steps:
        try:
            step()
        except OSError as exc:
            if exc.errno not in NOT_HERE:
                raise


if __name__ == "__main__":
    clear()
