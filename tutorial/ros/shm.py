"""Fast DDS's shared-memory files in /dev/shm: which a process uses, and removing those nobody uses.

On one machine, ROS 2's Fast DDS also talks through shared memory.  With
``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``, rmw_fastrtps always adds that
transport (``FASTDDS_BUILTIN_TRANSPORTS`` is not read then), so it cannot be
turned off here.  Its files in :data:`SHM_DIR`: per participant a segment
``fastrtps_<16 hex>`` and its lock file ``..._el``; per listening port
``fastrtps_port<N>``, a lock file ``..._el`` or ``..._sl`` and a semaphore
``sem.fastrtps_port<N>_mutex``.  A live owner holds ``flock()`` on the lock
file (how Fast DDS's ``fastdds shm clean`` tells a zombie).  A node that
ends cleanly removes its segment, and a port's files go when the last
process using it closes it; a node killed with SIGKILL closes nothing: its
own files stay, and so do those of the ports it had open.

The launcher (:mod:`tutorial.ros.launch`) notes which files its nodes use and,
once they are all gone, removes those nobody uses any more: Fast DDS's own
rules, applied only to the files its own nodes used.  A test session and
``make bench``, which kill nodes on purpose, remove the unused ones that
appeared while they ran (:func:`new_leftovers_removed`).
"""

from __future__ import annotations

import contextlib
import ctypes
import fcntl
import os
import re

SHM_DIR = "/dev/shm"
_SHM_SEGMENT = re.compile(r"fastrtps_[0-9a-z]{16}")
_SHM_PORT = re.compile(r"fastrtps_port[0-9]+")


def fast_dds_shm_files(pid: int, mapped: bool = True) -> set[str]:
    """Names of the Fast DDS files in :data:`SHM_DIR` that process ``pid`` holds open, and maps if ``mapped``.

    Read from ``/proc/<pid>/fd`` (its own segment's and ports' lock files:
    0.1 ms) and ``/proc/<pid>/maps`` (every segment and port it uses, its
    peers' too: a few ms).  Empty when the process is gone or not ours to
    read.  Any thread may call it.
    """
    prefix = SHM_DIR + "/fastrtps_"
    paths = set()
    try:
        if mapped:
            with open(f"/proc/{pid}/maps") as maps:
                paths.update(
                    line.split(maxsplit=5)[-1].rstrip("\n").removesuffix(" (deleted)")
                    for line in maps
                    if prefix in line
                )
        for fd in os.listdir(f"/proc/{pid}/fd"):
            with contextlib.suppress(OSError):
                paths.add(os.readlink(f"/proc/{pid}/fd/{fd}"))
    except OSError:
        pass
    return {os.path.basename(path) for path in paths if path.startswith(prefix)}


def remove_unused_fast_dds_shm(names) -> list[str]:
    """Remove the Fast DDS segments and ports among ``names`` that no live process uses; the files removed.

    ``names``: file names in :data:`SHM_DIR` (any of a segment's or port's
    files names it).  One is unused when none of its lock files is locked:
    its owner is gone.  Its lock files stay locked, and a port's mutex held,
    while its files are removed: a process that opens the same port just
    then waits, and never gets half of them.  Any thread may call it.
    """
    removed = []
    for base in sorted({name.removesuffix("_el").removesuffix("_sl") for name in names}):
        if _SHM_SEGMENT.fullmatch(base):  # a random name: nobody creates it again
            files, locks = [base, base + "_el"], [base + "_el"]
        elif _SHM_PORT.fullmatch(base):  # any process may open it again: under Fast DDS's port mutex
            files, locks = [base, base + "_el", base + "_sl", f"sem.{base}_mutex"], [base + "_el", base + "_sl"]
        else:
            continue
        with contextlib.ExitStack() as held:
            if _SHM_PORT.fullmatch(base) and not held.enter_context(_fast_dds_port_mutex(base)):
                continue  # a process is opening or creating it right now
            if not all(_lock_if_unused(os.path.join(SHM_DIR, lock), held) for lock in locks):
                continue  # its owner is alive
            for name in files:
                with contextlib.suppress(FileNotFoundError):
                    os.unlink(os.path.join(SHM_DIR, name))
                    removed.append(name)
    return removed


@contextlib.contextmanager
def _fast_dds_port_mutex(port: str):
    """Hold the mutex Fast DDS takes to open, create or remove ``port``; yields False if another process has it.

    It is a POSIX named semaphore, ``/dev/shm/sem.<port>_mutex``; the caller
    may remove that file while holding it, as Fast DDS creates it again when
    it next opens the port.
    """
    libc = ctypes.CDLL("libc.so.6", use_errno=True)
    libc.sem_open.restype = ctypes.c_void_p
    libc.sem_open.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_uint, ctypes.c_uint]
    libc.sem_trywait.argtypes = libc.sem_post.argtypes = libc.sem_close.argtypes = [ctypes.c_void_p]
    name = f"/{port}_mutex".encode()
    sem = libc.sem_open(name, os.O_CREAT, 0o644, 1)
    if sem is None or sem == ctypes.c_void_p(-1).value:  # SEM_FAILED
        yield False
        return
    try:
        if libc.sem_trywait(sem) != 0:
            yield False
            return
        try:
            yield True
        finally:
            libc.sem_post(sem)
    finally:
        libc.sem_close(sem)


def _lock_if_unused(path: str, held: contextlib.ExitStack) -> bool:
    """Take ``path``'s flock (kept until ``held`` closes) unless another process holds it; True if free or absent."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except FileNotFoundError:
        return True
    held.callback(os.close, fd)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    return True


def _names_now() -> set[str]:
    """The names in :data:`SHM_DIR` now (empty on a machine without it).  Any thread may call it."""
    try:
        return set(os.listdir(SHM_DIR))
    except FileNotFoundError:  # no /dev/shm: nothing of Fast DDS's to look after
        return set()


@contextlib.contextmanager
def new_leftovers_removed():
    """On leaving, remove the Fast DDS files that appeared in :data:`SHM_DIR` meanwhile and no live process uses.

    For a whole run that kills nodes on purpose (a benchmark suite): only
    files new since it began are looked at, and of those only the ones whose
    lock no live process holds are removed (:func:`remove_unused_fast_dds_shm`),
    also when the run ends with an error.  Whoever left them, they are
    nobody's any more.  Yields nothing.
    """
    before = _names_now()
    try:
        yield
    finally:
        remove_unused_fast_dds_shm(_names_now() - before)


def is_segment(name: str) -> bool:
    """Whether ``name`` is a participant's segment (not a port, not a lock file)."""
    return bool(_SHM_SEGMENT.fullmatch(name))
