"""The kernel keyrings out of a graded answer's reach: no note one submission leaves there reaches the next.

Linux keeps a user's keyring (``@u``), user-session keyring (``@us``) and
persistent keyring by user ID, not by process: they outlive the processes
that wrote them (the persistent one for days).  Two submissions graded in
turn as one job's user could pass a key between them, and a user given the
same ID later would find it.  So the grading kernel
(:mod:`tutorial.tools.grading.sealed_kernel`), before any answer runs, has
``keyctl(2)``, ``add_key(2)`` and ``request_key(2)`` refused to itself and
to every process it starts (:func:`refuse`: a seccomp filter made with
libseccomp, the system's library for them).  With no system call to reach
them, an answer can neither leave, read nor lock a key, and a key left there
before cannot be read either.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import errno
import os

KEY_SYSCALLS = ("keyctl", "add_key", "request_key")
SCMP_ACT_ALLOW = 0x7FFF0000
SCMP_ACT_ERRNO = 0x00050000  # | the errno the call returns
SCMP_FLTATR_CTL_TSYNC = 4  # the filter on every thread of the process, not only the calling one


MISSING = "grading needs libseccomp (Debian and Ubuntu: apt install libseccomp2)"


def libseccomp_name() -> str | None:
    """The file name of this system's libseccomp, or None where it has none.  Any thread."""
    return ctypes.util.find_library("seccomp")


def _libseccomp():
    name = libseccomp_name() or "libseccomp.so.2"
    try:
        lib = ctypes.CDLL(name, use_errno=True)
    except OSError as exc:
        raise OSError(f"{MISSING}: {name}: {exc}") from exc
    lib.seccomp_init.restype = ctypes.c_void_p
    lib.seccomp_init.argtypes = [ctypes.c_uint32]
    lib.seccomp_attr_set.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_uint32]
    lib.seccomp_syscall_resolve_name.argtypes = [ctypes.c_char_p]
    lib.seccomp_rule_add.argtypes = [ctypes.c_void_p, ctypes.c_uint32, ctypes.c_int, ctypes.c_uint]
    lib.seccomp_load.argtypes = [ctypes.c_void_p]
    lib.seccomp_release.argtypes = [ctypes.c_void_p]
    return lib


def refuse() -> None:
    """From now on, :data:`KEY_SYSCALLS` fail with EPERM in every thread of this process and in every process
    it starts.  For good: meant for the sealed kernel's start, before any answer runs.

    Needs no_new_privs (``setpriv --no-new-privs``, as the sandbox starts the kernel) or CAP_SYS_ADMIN.

    Raises:
        OSError: the filter could not be made or loaded (libseccomp missing, no no_new_privs).
    """
    lib = _libseccomp()
    filter_ = lib.seccomp_init(SCMP_ACT_ALLOW)
    if not filter_:
        raise OSError("seccomp_init failed")
    try:
        rc = lib.seccomp_attr_set(filter_, SCMP_FLTATR_CTL_TSYNC, 1)
        for name in KEY_SYSCALLS:
            if rc >= 0:
                number = lib.seccomp_syscall_resolve_name(name.encode())
                rc = lib.seccomp_rule_add(filter_, SCMP_ACT_ERRNO | errno.EPERM, number, 0)
        if rc >= 0:
            rc = lib.seccomp_load(filter_)
        if rc < 0:
            raise OSError(-rc, f"the keyrings' seccomp filter: {os.strerror(-rc)}")
    finally:
        lib.seccomp_release(filter_)
