"""The submissions ``make grade`` collects, copied out of the learners' reach first, each checked for who handed
it in.

nbgrader names a submission after whoever the learner's own server says they are (``NAME+ASSIGNMENT+TIME+…``
in the exchange's ``inbound/``), and a learner can say anyone (``nbgrader submit --student NAME``); the newest
submission under a name is the one collected, so a forged one would replace another learner's work.  A
learner also owns their submission's folder until it is collected, and could change it, or plant links in it,
while the teacher's grading reads it.  So before ``nbgrader collect``, :func:`stage` copies every submission it
accepts into a folder of the course that only the teacher can write (``staged-exchange/``), and ``collect``
reads that copy:

- the copy holds folders and regular files only, opened without following any link (a submission holding a
  link or a special file is refused), no larger than nbgrader allows; its ``timestamp.txt`` the time in its name;
- where learners are Unix users of this machine (the hub's ``users`` spawner), the submission's folder must be
  owned by the user of the name it bears;
- in containers, where every learner is ``jovyan`` inside, each learner hands in to a folder of their own that the hub
  named (``inbound-by-learner/NAME``, :mod:`container_exchange`): a submission in it must bear that name;
- its name must read the same as nbgrader reads it, with a time nbgrader can read (one that is not would stop
  ``collect`` for the whole class); one that cannot be copied (too deep, changed while copied) is refused.

Where every learner is one user (the trial's spawner) and the name is no account of this machine, who handed
it in cannot be told: the submission is staged, and its name reported.  Nothing in the exchange is moved or
changed.  The teacher's thread calls all of it.
"""

from __future__ import annotations

import os
import pwd
import shutil
import stat
from pathlib import Path

STAGED = "staged-exchange"
BY_LEARNER = "inbound-by-learner"  # the containers' inbound folders (course/container_exchange.py)
MAX_BYTES = 100_000 * 1000  # nbgrader's own default limit of a submission (1000 * max_dir_size, in bytes)
FIRST_LEARNER_UID = 1000  # below: system accounts (Debian's), never a learner


class Refused(Exception):
    """A submission not staged; the message says why."""


def stage(exchange_course: Path, course: Path, max_bytes: int = MAX_BYTES) -> tuple[Path, list[str], list[str]]:
    """Copy the submissions of ``exchange_course`` (the exchange's folder of this course) that pass into
    ``course/staged-exchange/<course id>/inbound``; ``max_bytes``: the course's limit of one (nbgrader's
    ``1000 * max_dir_size``: ``collect`` stops for the whole class on a larger one).

    Returns:
        (the staged exchange's root, for ``nbgrader collect --Exchange.root``; one line per refused
        submission, "NAME+…: why"; the names whose author cannot be told)
    """
    root = course / STAGED
    shutil.rmtree(root, ignore_errors=True)
    staged = root / exchange_course.name / "inbound"
    staged.mkdir(mode=0o700, parents=True)
    os.chmod(root, 0o700)
    refused: list[str] = []
    unchecked: set[str] = set()
    if not exchange_course.is_dir():
        return root, refused, []
    _require_teachers(exchange_course)
    inbound = exchange_course / "inbound"
    if inbound.is_dir():
        for name in sorted(os.listdir(inbound)):
            learner = name.split("+")[0]
            uid = _uid_of(learner)
            try:
                _stage_one(inbound, name, staged, uid, max_bytes)
            except Refused as why:
                refused.append(f"{name}: {why}")
            else:
                if uid is None:
                    unchecked.add(learner)
    folders = exchange_course / BY_LEARNER
    if folders.is_dir():
        _require_teachers(folders)
        for learner in sorted(os.listdir(folders)):
            own = folders / learner
            if own.is_symlink() or not own.is_dir():
                refused.append(f"{BY_LEARNER}/{learner}: not a folder")
                continue
            for name in sorted(os.listdir(own)):
                try:
                    named = _parts(name)[0]
                    if named != learner:
                        raise Refused(f"handed in by {learner}, not {named}")
                    _stage_one(own, name, staged, None, max_bytes)
                except Refused as why:
                    refused.append(f"{name}: {why}")
    return root, refused, sorted(unchecked)


def _uid_of(name: str) -> int | None:
    """The uid of the learner account ``name``, if this machine has one (a system account is none)."""
    try:
        uid = pwd.getpwnam(name).pw_uid
    except KeyError:
        return None
    return uid if uid >= FIRST_LEARNER_UID else None


def _require_teachers(folder: Path) -> None:
    """``folder`` must be the teacher's: not a link, owned by this user or root, writable by nobody else (a
    learner could otherwise put a course folder of their own in its place)."""
    st = folder.lstat()
    if stat.S_ISLNK(st.st_mode) or st.st_uid not in (0, os.geteuid()) or st.st_mode & 0o022:
        raise RuntimeError(
            f"{folder} is not the teacher's (a link, or owned or writable by someone else): not graded; "
            "release the assignment again with nbgrader, or make it the teacher's and writable by them alone"
        )


def _parts(name: str) -> list[str]:
    """NAME, ASSIGNMENT, TIME (and nbgrader's random part) of a submission's folder name, read as nbgrader's
    ``collect`` reads them (``rsplit("+", 3)``); :class:`Refused` when the two readings could differ."""
    from nbgrader.utils import parse_utc

    parts = name.split("+")
    if len(parts) not in (3, 4):
        raise Refused("not a submission's name")
    try:
        parse_utc(parts[2])
    except Exception as exc:  # noqa: BLE001 - any failure to read it would stop nbgrader collect
        raise Refused("its time cannot be read") from exc
    return parts


def _stage_one(folder: Path, name: str, staged: Path, owner: int | None, max_bytes: int) -> None:
    """Copy submission ``name`` of ``folder`` into ``staged``, refusing it (:class:`Refused`) where it fails a
    rule; ``owner``: the uid that must own it, if known.  Its ``timestamp.txt`` is the time in its name (one
    nbgrader cannot read would stop later collections)."""
    parts = _parts(name)
    parent = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    try:
        try:
            fd = os.open(name, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW, dir_fd=parent)
        except OSError as exc:
            raise Refused("not a folder") from exc
        try:
            if owner is not None and (got := os.fstat(fd).st_uid) != owner:
                raise Refused(f"handed in by {_user_name(got)}, not {parts[0]}")
            dest = staged / name
            dest.mkdir(mode=0o700)
            try:
                _copy(fd, dest, [max_bytes], owner)
                (dest / "timestamp.txt").write_text(parts[2])
            except (Refused, OSError, RecursionError) as exc:
                shutil.rmtree(dest, ignore_errors=True)
                if isinstance(exc, Refused):
                    raise
                raise Refused(f"could not be copied ({type(exc).__name__})") from exc
        finally:
            os.close(fd)
    finally:
        os.close(parent)


def _user_name(uid: int) -> str:
    try:
        return pwd.getpwuid(uid).pw_name
    except KeyError:
        return f"uid {uid}"


def _copy(src_fd: int, dest: Path, left: list[int], owner: int | None) -> None:
    """Copy the folder open as ``src_fd`` into ``dest``: folders and regular files only, each opened relative
    to its folder without following a link, so nothing the learner changes meanwhile leads outside it.  A
    file that is not ``owner``'s (when known) is refused too, and where no owner is known, a file with a
    second name (a hard link): either may be someone else's work."""
    for entry in os.scandir(src_fd):
        st = os.stat(entry.name, dir_fd=src_fd, follow_symlinks=False)
        if stat.S_ISDIR(st.st_mode):
            fd = os.open(entry.name, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW, dir_fd=src_fd)
            try:
                (dest / entry.name).mkdir(mode=0o700)
                _copy(fd, dest / entry.name, left, owner)
            finally:
                os.close(fd)
        elif stat.S_ISREG(st.st_mode):
            try:
                fd = os.open(entry.name, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK, dir_fd=src_fd)
            except OSError as exc:
                raise Refused(f"holds {entry.name!r}, which could not be opened as a file") from exc
            try:
                got = os.fstat(fd)
                if not stat.S_ISREG(got.st_mode):
                    raise Refused(f"holds {entry.name!r}, which is no regular file")
                if owner is not None and got.st_uid != owner:
                    raise Refused(f"holds {entry.name!r}, which is {_user_name(got.st_uid)}'s")
                if owner is None and got.st_nlink != 1:  # another name of a file elsewhere: whose, unknown
                    raise Refused(f"holds {entry.name!r}, a file with another name too (a hard link)")
                with open(dest / entry.name, "wb") as out, os.fdopen(os.dup(fd), "rb") as data:
                    while chunk := data.read(1 << 20):
                        left[0] -= len(chunk)
                        if left[0] < 0:
                            raise Refused("larger than the course allows (nbgrader's max_dir_size)")
                        out.write(chunk)
            finally:
                os.close(fd)
        else:
            raise Refused(f"holds {entry.name!r}, a link or a special file")
