"""The grading kernel's seal: a check's verdict leaves the kernel only if the teacher's own code made it.

nbgrader grades a test cell by whether it raised, in the same Python
process as the learner's answer, so one line of an answer (rebinding a
check, patching ``Result.require``, silencing IPython's traceback) could
turn a failing check into full points.  When ``course/grade.py`` grades,
each submission's kernel starts sealed (:mod:`tutorial.exercises.sealed_kernel`),
before any cell runs, and the grade of a check cell comes from the seal's
signed verdicts, not from the cell's output:

* :func:`install` snapshots the teacher's code: every ``tutorial`` module's
  names, the classes and functions in them (code, defaults, closures),
  ``builtins``; and an audit hook (PEP 578: it cannot be removed) with
  private builtins and no name any Python code can reach.
* ``grade()`` announces each check (``rtt.check_begin``) and its result
  (``rtt.result``); the hook takes them only from the teacher's ``grade``,
  called by one of the teacher's check functions.  ``Result.require()``
  asks for the verdict (``rtt.verdict``), taken only from the teacher's
  ``require`` called by a statement compiled exactly like the test cell's
  call.  Each time the snapshot is compared, object by object.
* During a check, the hook refuses what would let an answer read or change
  the check from inside: frames of the answer's own code, the garbage
  collector's object lists, tracing; it refuses at any time an answer's
  ``ctypes`` (raw memory), a second audit hook, and changing the code or
  defaults of the teacher's functions, and it notes (without refusing) an answer's connections,
  processes and files outside its folder.
* Each verdict (``begin``, ``verdict``, ``note``) goes out as a line signed with
  a key only the grader and the hook hold (HMAC-SHA256), on a pipe of the
  grader's; ``course/sandbox.py`` reads and checks it.

What the seal does not stop: code that changes a check's objects *and*
puts them back within one call from the check, or from a thread of its
own while the check runs (the snapshot is compared at the check's start
and end), and frames reached through a library function that walks the
stack (``traceback.walk_stack``), which can read a check's expected values.
The hook itself never calls an answer's code (no ``str()``, no library
function an answer could replace), so nothing runs unwatched inside it.  The sandbox (``course/sandbox.py``)
bounds what such code could reach.  Main thread only: ``install`` runs once,
before the kernel starts.
"""

from __future__ import annotations

import builtins
import importlib
import os
import pkgutil
import sys
import types

# What a verdict line carries: the fields below, tab-separated, then the HMAC-SHA256 of the line so far.
BEGIN, VERDICT, NOTE = "begin", "verdict", "note"
REFUSED_IN_CHECK = frozenset(
    {"sys._current_frames", "gc.get_objects", "gc.get_referrers", "gc.get_referents", "sys.settrace", "sys.setprofile"}
)
FRAME_ATTRIBUTES = frozenset({"tb_frame", "gi_frame", "cr_frame", "ag_frame"})
NOTED = frozenset({"socket.connect", "socket.sendto", "os.fork", "os.forkpty", "subprocess.Popen", "os.posix_spawn"})
NOT_COMPARED = frozenset(
    {"_", "input", "exit", "quit", "display", "get_ipython", "__IPYTHON__", "copyright", "credits"}
)


def trusted_modules(checks: list[str] | None = None) -> list[types.ModuleType]:
    """The check modules ``checks`` (default: every module of ``tutorial.exercises``) and the grader, imported
    with what they import; then every ``tutorial`` module imported so far: what the checks run."""
    import tutorial.exercises as package

    if checks is None:
        checks = [f"tutorial.exercises.{i.name}" for i in pkgutil.iter_modules(package.__path__)]
    for name in ["tutorial.exercises.grader", *checks]:
        if name.rsplit(".", 1)[-1] not in ("seal", "sealed_kernel"):
            importlib.import_module(name)
    return [m for name, m in sorted(sys.modules.items()) if m is not None and name.split(".")[0] == "tutorial"]


def install(
    key: bytes,
    fd: int,
    test_calls: list[str],
    hidden: list[str] = (),
    checks: list[str] | None = None,
    seed: str = "",
) -> None:
    """Seal this process: snapshot the teacher's code and add the audit hook that signs verdicts on ``fd``.

    ``key``: the HMAC key (the grader's; never stored where Python code can read it); ``fd``: the pipe's
    write end; ``test_calls``: each test cell's last line as nbgrader gives it (``check_x(answer).require()``);
    ``hidden``: folders the sandbox hides (the course's, ...): an answer opening a path there is noted;
    ``checks``: the modules the test cells import their checks from (default: all of them); ``seed``: this
    learner's seed of hidden cases, given only to a teacher's check (``grader.hidden_random``).

    Raises:
        RuntimeError: called twice in one process (the second audit hook is refused).
    """
    import _hashlib
    import _thread

    from tutorial.exercises import grader

    modules = trusted_modules(checks)
    package = os.path.dirname(os.path.dirname(os.path.realpath(grader.__file__)))  # tutorial/
    roots = tuple(os.path.realpath(p) + os.sep for p in {sys.prefix, sys.base_prefix, package})
    repository = os.path.dirname(package)
    readable = tuple(os.path.join(repository, p) + os.sep for p in ("project", "model"))
    calls = [compile(text, "<test cell>", "single") for text in test_calls]
    private = {  # the hook's globals: an answer's changes to builtins or to this module do not reach it
        "__builtins__": dict(builtins.__dict__),
        "types": types,
        "getcwd": os.getcwd,
        "get_ident": _thread.get_ident,
        **{name: globals()[name] for name in ("BEGIN", "VERDICT", "NOTE", "NOT_COMPARED", "NOTED")},
        **{name: globals()[name] for name in ("REFUSED_IN_CHECK", "FRAME_ATTRIBUTES")},
    }
    make = types.FunctionType(_make_hook.__code__, private, "_make_hook")
    hidden = tuple(h.rstrip("/") + "/" for h in hidden)
    hook = make(
        key,
        fd,
        modules,
        roots,
        readable,
        hidden,
        seed,
        calls,
        grader,
        builtins.__dict__,
        _hashlib.hmac_digest,
        os.write,
        sys._getframe,
    )
    sys.addaudithook(hook)


def _make_hook(
    key, fd, modules, roots, readable, hidden, seed, calls, grader, builtin_names, hmac_digest, write, getframe
):  # noqa: C901
    """The audit hook, its state in closures only (made with private globals by :func:`install`)."""
    trusted: dict[int, object] = {}  # id -> object (kept alive, so an id is never reused)
    snapshot: list[tuple] = []  # (where, namespace, name, object): compared by identity
    function_parts: list[tuple] = []  # (function, code, defaults, kwdefaults, closure contents)

    def remember_function(where, f):
        cells = tuple(c.cell_contents for c in (f.__closure__ or ()) if _filled(c))
        function_parts.append((where, f, f.__code__, f.__defaults__, f.__kwdefaults__, cells))
        trusted[id(f)] = f

    def _filled(cell):
        try:
            cell.cell_contents  # noqa: B018 - an empty cell raises
        except ValueError:
            return False
        return True

    check_modules = {m.__name__ for m in modules if any(n.startswith("check_") for n in m.__dict__) and m is not grader}

    def uses(code, space):
        """The names of ``space`` that ``code`` reads, and what those read in turn (functions, classes)."""
        names, seen, stack = set(), set(), [code]
        while stack:
            c = stack.pop()
            if id(c) in seen:
                continue
            seen.add(id(c))
            names.update(c.co_names)
            stack.extend(k for k in c.co_consts if isinstance(k, types.CodeType))
            for n in c.co_names:
                value = space.get(n)
                if isinstance(value, types.FunctionType):
                    stack.append(value.__code__)
                elif isinstance(value, type):
                    stack.extend(v.__code__ for v in vars(value).values() if isinstance(v, types.FunctionType))
        return names

    for module in modules:
        space = module.__dict__
        for name, value in list(space.items()):
            if name.startswith("__"):
                continue
            if module.__name__.startswith("tutorial.exercises") or isinstance(
                value, (type, types.FunctionType, types.ModuleType, types.BuiltinFunctionType)
            ):
                snapshot.append((module.__name__, space, name, value))
            if isinstance(value, types.FunctionType) and value.__module__ == module.__name__:
                remember_function(f"{module.__name__}.{name}", value)
            elif isinstance(value, type) and value.__module__ == module.__name__:
                trusted[id(value)] = value
                for attr, member in list(value.__dict__.items()):
                    if attr in ("__dict__", "__weakref__", "__doc__"):
                        continue
                    snapshot.append((f"{module.__name__}.{name}", value.__dict__, attr, member))
                    inner = member.__func__ if isinstance(member, (staticmethod, classmethod)) else member
                    if isinstance(inner, types.FunctionType):
                        remember_function(f"{module.__name__}.{name}.{attr}", inner)
    for name, value in list(builtin_names.items()):
        if name not in NOT_COMPARED:
            snapshot.append(("builtins", builtin_names, name, value))
    check_codes = {  # each check's code -> (its module, the module's names it uses)
        id(f.__code__): (f.__code__, m.__name__, uses(f.__code__, m.__dict__))
        for m in modules
        if m.__name__ in check_modules
        for n, f in m.__dict__.items()
        if n.startswith("check_") and isinstance(f, types.FunctionType)
    }
    grade_code, require_code = grader.grade.__code__, grader.Result.require.__code__
    result_type = grader.Result
    state = {"checks": 0, "refused": [], "results": {}, "number": ""}
    suspecting = {grader._suspect.__code__}
    seed_code = grader.hidden_random.__code__
    missing = object()

    def changed(check=None):
        """What differs from the snapshot; of the check modules, only what ``check`` (a code id) uses."""
        module, used = check_codes[check][1:] if check in check_codes else (None, ())
        out = []
        for where, space, name, value in snapshot:
            if where in check_modules and (where != module or name not in used):
                continue  # another check's module, or a name this check does not use
            if space.get(name, missing) is not value:
                out.append(f"{where}.{name} was replaced")
        for where, f, code, defaults, kwdefaults, cells in function_parts:
            owner, _, short = where.rpartition(".")
            if owner in check_modules and (owner != module or short not in used):
                continue
            now = tuple(c.cell_contents for c in (f.__closure__ or ()) if _filled(c))
            if f.__code__ is not code or f.__defaults__ is not defaults or f.__kwdefaults__ is not kwdefaults:
                out.append(f"{where}'s code or defaults were changed")
            elif len(now) != len(cells) or any(a is not b for a, b in zip(now, cells)):
                out.append(f"{where}'s closure was changed")
        return out

    def send(*fields):
        line = "\t".join(str(f).replace("\t", " ").replace("\n", " ") for f in fields)
        mac = hmac_digest(key, line.encode(), "sha256").hex()
        try:
            write(fd, (line + "\t" + mac + "\n").encode())
        except OSError:
            pass  # the pipe closed or taken over by the answer: no verdict reaches the grader, which gives 0

    def learner(frame):
        name = frame.f_code.co_filename
        if name.startswith("<frozen "):
            return False
        return not name.startswith(roots)

    def absolute(path):
        """``path`` made absolute and normal here, never by a library function an answer could replace."""
        parts = []
        for part in (path if path.startswith("/") else getcwd() + "/" + path).split("/"):  # noqa: F821
            if part == "..":
                parts = parts[:-1]
            elif part and part != ".":
                parts.append(part)
        return "/" + "/".join(parts)

    def learner_near(frame, depth=6):
        """Whether answer code called this within ``depth`` frames (through IPython's open(), socket.py, ...)."""
        while frame is not None and depth > 0:
            if learner(frame):
                return True
            frame, depth = frame.f_back, depth - 1
        return False

    def number_of(exercise):
        if type(exercise) is not str:
            return "?"  # never str() of an answer's own object: its __str__ would run inside the hook
        words = exercise.split()
        return words[1].rstrip(",") if len(words) > 1 and words[0] == "Exercise" else "?"

    def same_call(code):
        for call in calls:
            if code.co_code == call.co_code and code.co_names == call.co_names and code.co_consts == call.co_consts:
                return True
        return False

    def here():
        """The exercise whose check is running, or "" (then the grader gives a note to the next check)."""
        return state["number"] if state["checks"] else ""

    def refuse(what):
        state["refused"].append(what)
        send(NOTE, "refused", what, here())
        raise RuntimeError(f"the grader's sandbox refused: {what}")

    busy = set()  # the threads inside the hook: what it does itself raises events, which it lets pass

    def hook(event, args):
        if not (event.startswith("rtt.") or event in WATCHED or event.startswith("ctypes.")):
            return
        me = get_ident()  # noqa: F821 - a private global
        if me in busy:
            return
        busy.add(me)
        try:
            act(event, args)
        finally:
            busy.discard(me)

    def act(event, args):  # noqa: C901 - one branch per event
        try:
            caller = getframe(2)  # 0: act, 1: hook, 2: the code that raised the event
        except ValueError:
            return  # raised from no Python code at all: nobody's answer
        if event == "rtt.check_begin":
            if caller.f_code is grade_code:
                state["checks"] += 1
                state["refused"] = []
                state["number"] = number_of(args[0])
                outer = caller.f_back
                state["begin_changes"] = changed(id(outer.f_code) if outer is not None else None)
                send(BEGIN, number_of(args[0]))
        elif event == "rtt.result":
            result = args[0]
            if caller.f_code is grade_code and type(result) is result_type:
                outer = caller.f_back
                genuine = outer is not None and id(outer.f_code) in check_codes
                check = id(outer.f_code) if genuine else None
                reasons = list(state.get("begin_changes", [])) + changed(check) + list(state["refused"])
                if not genuine:
                    reasons.append("grade() was not called by one of the teacher's checks")
                record = (result, number_of(result.exercise), bool(result.passed), reasons, check)
                state["results"][id(result)] = record
                state["checks"] = max(0, state["checks"] - 1)
        elif event == "rtt.verdict":
            result = args[0]
            record = state["results"].get(id(result))
            if caller.f_code is not require_code or record is None:
                exercise = result.__dict__.get("exercise") if type(result) is result_type else None
                said = number_of(exercise) if type(exercise) is str else "?"  # never an answer's own str
                send(NOTE, "tampering", "a verdict not made by the teacher's check and require()", said)
                return
            _, number, passed, reasons, check = record
            statement = caller.f_back
            reasons = list(reasons) + changed(check)
            if statement is None or not same_call(statement.f_code):
                reasons.append("require() was not called by the test cell's statement")
            reasons = list(dict.fromkeys(reasons))
            send(VERDICT, number, int(passed), int(not reasons), "; ".join(reasons[:3]))
        elif event == "rtt.seed":
            outer = caller.f_back
            if seed and caller.f_code is seed_code and outer is not None and id(outer.f_code) in check_codes:
                if type(args[0]) is list:
                    args[0].append(seed)
        elif event == "rtt.suspect":
            if caller.f_code in suspecting:
                send(NOTE, "tampering", f"an answer returned {args[0]}", here())
        elif event == "sys.addaudithook":
            refuse("a second audit hook")
        elif event in ("object.__setattr__", "object.__delattr__"):
            if id(args[0]) in trusted:
                refuse(f"changing {getattr(args[0], '__qualname__', '?')}.{args[1]}")
        elif event in ("compile", "code.__new__"):
            filename = args[1] if type(args[1]) is str else ""
            if learner(caller) and (filename.startswith(roots) or filename.startswith("<frozen")):
                refuse(f"code claiming to be the library's ({filename})")
        elif event == "open":
            path = args[0]
            if type(path) is not str:
                return  # a file descriptor, or bytes: not an answer's way to a path here
            path = absolute(path)
            if "/proc/" in path and path.endswith("/mem"):
                refuse(f"opening {path}")
            allowed = ALLOWED + roots + readable + (getcwd() + "/",)  # noqa: F821 - a private global
            outside = not path.startswith(allowed) or (path.startswith(hidden) and not path.startswith(roots))
            if outside and learner_near(caller):
                send(NOTE, "outside", f"opened {path}", here())
        elif event.startswith("ctypes.") and learner(caller):
            refuse(event)  # raw memory: the seal's key, or any object
        elif event in NOTED:
            if learner_near(caller):
                send(NOTE, "network" if event.startswith("socket") else "processes", event, here())
        elif state["checks"] > 0:
            if event in REFUSED_IN_CHECK and learner_near(caller, 3):
                refuse(f"{event} during a check")
            elif event == "sys._getframe" and (
                learner(caller) or (learner(args[0]) and caller.f_back is not None and learner(caller.f_back))
            ):  # the answer's own call, or a library function's it called directly (inspect.currentframe())
                refuse("reading frames during a check")
            elif event == "object.__getattr__" and args[1] in FRAME_ATTRIBUTES and learner(caller):
                refuse(f"reading {args[1]} during a check")

    WATCHED = (
        REFUSED_IN_CHECK
        | NOTED
        | {"sys.addaudithook", "object.__setattr__", "object.__delattr__", "compile", "code.__new__", "open"}
        | {"sys._getframe", "object.__getattr__"}
    )
    ALLOWED = ("/tmp/", "/dev/", "/proc/self/", "/sys/", "/etc/", "/usr/", "/lib", "/run/")
    return hook
