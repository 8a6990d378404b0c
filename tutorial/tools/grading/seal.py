"""The grading kernel's seal: a check's verdict leaves the kernel only if the teacher's own code made it.

nbgrader grades a test cell by whether it raised, in the same Python
process as the learner's answer, so one line of an answer (rebinding a
check, patching ``Result.require``, silencing IPython's traceback) could
turn a failing check into full points.  When ``course/grade.py`` grades,
each submission's kernel starts sealed (:mod:`tutorial.tools.grading.sealed_kernel`,
started by :mod:`tutorial.tools.grading.sandbox`) before any cell runs, and the grade of a check cell
comes from the seal's signed verdicts, not from the cell's output:

* :func:`install` snapshots the teacher's code: every ``tutorial`` module's
  names, the classes and functions in them (code, defaults, closures),
  ``builtins``; and an audit hook (PEP 578: it cannot be removed) with
  private builtins and no name any Python code can reach.
* ``grade()`` announces each check (``rtt.check_begin``) and its result
  (``rtt.result``); the hook takes them only from the teacher's ``grade``
  (its code, with its module's real globals),
  called by one of the teacher's check functions.  ``Result.require()``
  asks for the verdict (``rtt.verdict``), taken only from the teacher's
  ``require`` called by a statement compiled exactly like the test cell's
  call.  Each time the snapshot is compared, object by object.
* The hook refuses what would let an answer read or change the checks, or
  the hook, from inside: after a check, the first frame an answer reads
  clears every ended frame of the checks' code (one kept from the check
  leads there through ``f_back``); in any thread but the kernel's main one (an answer's thread may run a C
  callable, leaving no answer frame on its stack), the lists of every object and of every thread's frames,
  and a running check's frames; during a check, frames taken by the answer's own
  code, or by a library for it while the answer runs (``traceback.walk_stack``,
  ``inspect.stack``: from any frame, ``f_back`` and ``f_locals``, which Python
  does not audit, lead to the check's values), and a check's verdict is not
  the teacher's if an answer's paused generator had its frame taken before
  (resumed inside the check, that frame leads there too; one Python made
  for an exception inside it, held by nothing else, is not); at any time, an
  answer's ``ctypes`` and ``/proc/*/mem`` (raw memory), the garbage
  collector's object lists, tracers, other threads' frames, the hook's own
  frames in a traceback, a second audit hook, and changing the code or
  defaults of the teacher's functions.  It notes (without refusing)
  an answer's connections, processes and files outside its folder.
* Signal handlers: Python hands a handler the running frame with no audit
  event.  :func:`install` replaces ``_signal.signal`` and
  ``_imp.create_builtin`` with gates to the hook, which alone holds the real
  functions: it sets SIG_DFL, SIG_IGN, ``default_int_handler`` and the
  kernel's own handler (ipykernel's ``handle_sigint``, by its code object), and refuses any other and
  a second ``_signal`` or ``_imp`` module.  A handler that is not the
  kernel's at a check's start or end makes its verdict not the teacher's.
* Each verdict (``begin``, ``verdict``, ``note``) goes out as a line signed with
  a key only the grader and the hook hold (HMAC-SHA256), on a pipe of the
  grader's; :mod:`tutorial.tools.grading.sandbox` reads and checks it.

While grading, the checks of :data:`tutorial.tools.grading.judge.JUDGED` (every
exercise's) run in a process of their own, the judge, exchanging only data
with the answer's, so the seal's verdicts decide no exercise of the course.
What it does for them: as each judged check begins and ends asking the
kernel (an ``rtt.judged`` event from :mod:`tutorial.tools.grading.judged`),
it compares what the teacher's check and its experiments use (their
module's names, the experiments by name, the grader, the standard modules)
with the snapshot, and notes a change as tampering, for that check.

What the seal does not stop (one process is no wall):

* reading or writing the process's memory without an audit event: NumPy's
  array interface (``__array_interface__`` with any address) and
  ``ctypes.cast`` of an address reach every byte, the key's among them;
* code that changes a check's objects *and* puts them back within one call
  from the check, or from a thread of its own while the check runs (the
  snapshot is compared at the check's start and end);
* the few lines where the hook asks who raised an event inside it: code
  run there (the kernel's own SIGINT handler, during an asynchronous cell,
  which an answer can lead into its code through the kernel's attributes)
  can read the hook's frames (about one landing in five in
  ``tests/test_seal.py``'s timer).

The sandbox (:mod:`tutorial.tools.grading.sandbox`) bounds what such code
could reach outside the kernel.  The hook itself calls no answer's code (no
``str()``, no library function an answer could replace); code that runs
inside it unasked (a signal's handler, a finalizer) may do none of what it
watches.

The module is over 400 lines and still one job: the hook and all it keeps
are closures of one function (:func:`_make_hook`), which no other module,
and no answer, can reach.  Main thread only: ``install`` runs once, before
the kernel starts.
"""

from __future__ import annotations

import ast
import builtins
import gc
import importlib
import importlib.util
import inspect
import os
import pkgutil
import sys
import types

# What a verdict line carries: the fields below, tab-separated, then the HMAC-SHA256 of the line so far.
BEGIN, VERDICT, NOTE = "begin", "verdict", "note"
FRAME_ATTRIBUTES = frozenset({"tb_frame", "gi_frame", "cr_frame", "ag_frame"})
# While an answer runs inside a check, a library may take a frame only to read it itself (its caller's file, line
# or module): these functions, each (end of its file's path, qualified name), through the wrappers below.  Any other
# frame taken then (traceback.walk_stack, walk_tb, inspect.stack, ...) could be handed to the answer, and from it
# f_back and f_locals, which Python does not audit, lead to the check's own values: refused.
FRAME_CONSUMERS = frozenset(
    {
        ("/logging/__init__.py", "Logger.findCaller"),
        ("/rclpy/impl/rcutils_logger.py", "CallerId.__new__"),
        ("/collections/__init__.py", "namedtuple"),
        ("/typing.py", "_caller"),
        ("/enum.py", "EnumType._create_"),
        ("/warnings.py", "warn"),
        ("/numpy/lib/_index_tricks_impl.py", "AxisConcatenator.__getitem__"),
        ("/numpy/matrixlib/defmatrix.py", "bmat"),
        ("/matplotlib/_api/__init__.py", "warn_external"),  # its warning's stack level, on Python 3.11
        ("/scipy/_lib/_bunch.py", "_make_tuple_bunch"),  # its class's module, as namedtuple's
        *(("/traceback.py", name) for name in ("print_stack", "extract_stack", "format_stack", "clear_frames")),
    }
)
# traceback's formatting (print_exc, logging's exc_info): its lines, and the frames' locals only if asked for them
TRACEBACK_LINES = ("/traceback.py", "StackSummary._extract_from_extended_frame_gen")
FRAME_WRAPPERS = frozenset(
    {
        ("/inspect.py", "currentframe"),
        ("/logging/__init__.py", "<lambda>"),
        *(("/traceback.py", name) for name in ("walk_stack", "walk_tb", "_walk_tb_with_full_positions")),
        ("/traceback.py", "StackSummary.extract.<locals>.extended_frame_gen"),
    }
)
NOTED = frozenset({"socket.connect", "socket.sendto", "os.fork", "os.forkpty", "subprocess.Popen", "os.posix_spawn"})
# Python's and NumPy's modules the checks compute with and draw hidden cases from: every name of theirs is
# snapshotted too (``random.Random = ...`` once left every check with no hidden case; ``numpy.allclose = ...``
# would make a comparison say yes).  Other libraries the lessons run (rclpy, MuJoCo) are not.
STANDARD_MODULES = ("math", "random", "numpy", "numpy.linalg")
# What the kernel's side of the judge and the wire call (their code, not their data: tempfile sets a global of its
# own on first use): replaced, they could send the judge what a right answer's experiment would
JUDGE_MODULES = ("functools", "socket", "tempfile", "shutil", "json", "base64", "dataclasses")
NOT_COMPARED = frozenset(
    {"_", "input", "exit", "quit", "display", "get_ipython", "__IPYTHON__", "copyright", "credits"}
)


def trusted_modules(checks: list[str] | None = None) -> list[types.ModuleType]:
    """The check modules ``checks`` (default: every module of ``tutorial.exercises``) and the grader, imported
    with what they import; then every ``tutorial`` module imported so far: what the checks run."""
    import tutorial.exercises as package

    if checks is None:
        checks = [f"tutorial.exercises.{i.name}" for i in pkgutil.iter_modules(package.__path__)]
    wanted, done = ["tutorial.exercises.grader", *checks], set()
    while wanted:  # each module, and the tutorial modules it imports anywhere (inside a check, lazily) too
        name = wanted.pop()
        if name in done:
            continue
        done.add(name)
        module = importlib.import_module(name)
        if name.startswith("tutorial.exercises"):
            wanted += _tutorial_imports(module)
    return [m for name, m in sorted(sys.modules.items()) if m is not None and name.split(".")[0] == "tutorial"]


def _tutorial_imports(module: types.ModuleType) -> list[str]:
    """The ``tutorial`` modules ``module``'s source imports, at its top or inside a function."""
    tree = ast.parse(inspect.getsource(module))
    names = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("tutorial"):
            names.append(node.module)
            names += [f"{node.module}.{a.name}" for a in node.names if _find(f"{node.module}.{a.name}")]
        elif isinstance(node, ast.Import):
            names += [a.name for a in node.names if a.name.startswith("tutorial")]
    return names


def _find(name: str) -> bool:
    """Whether ``name`` is a module (``from package import name`` may also import a module)."""
    try:
        return importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):
        return False


def _gated_signal(signalnum, handler, /):
    """``_signal.signal`` in a sealed process: the hook sets ``handler`` if it is the kernel's (the real function
    is the hook's alone).  Raises RuntimeError when the seal refuses it, else as ``signal.signal``."""
    previous = []
    sys.audit("rtt.signal", signalnum, handler, previous)
    return previous[0]


def _gated_create_builtin(spec, /):
    """``_imp.create_builtin`` in a sealed process: a new ``_signal`` (with a real ``signal()`` of its own) or
    ``_imp`` is refused, any other built-in module made as before."""
    made = []
    sys.audit("rtt.create_builtin", spec, made)
    return made[0]


def _kernels_handler_codes() -> tuple:
    """The code of the one Python signal handler the kernel sets while it runs: ipykernel's ``handle_sigint``
    around an asynchronous cell, which hands its frame argument on to nothing.  Taken from ipykernel's module
    as imported before the seal (:mod:`~tutorial.tools.grading.sealed_kernel` imports it first); none if it
    was not."""
    module = sys.modules.get("ipykernel.ipkernel")
    method = getattr(getattr(module, "IPythonKernel", None), "_cancel_on_sigint", None)
    code = getattr(getattr(method, "__wrapped__", None), "__code__", None)
    return tuple(
        k for k in getattr(code, "co_consts", ()) if isinstance(k, types.CodeType) and k.co_name == "handle_sigint"
    )


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
    import _imp
    import _signal
    import _thread

    from tutorial.exercises import grader

    modules = trusted_modules(checks)
    modules += [sys.modules[name] for name in STANDARD_MODULES if name in sys.modules]  # the checks imported them
    modules += [importlib.import_module(name) for name in JUDGE_MODULES]
    package = os.path.dirname(os.path.dirname(os.path.realpath(grader.__file__)))  # tutorial/
    roots = tuple(os.path.realpath(p) + os.sep for p in {sys.prefix, sys.base_prefix, package})
    repository = os.path.dirname(package)
    readable = tuple(os.path.join(repository, p) + os.sep for p in ("project", "model"))
    calls = [compile(text, "<test cell>", "single") for text in test_calls]
    private = {  # the hook's globals: an answer's changes to builtins or to this module do not reach it
        "__builtins__": dict(builtins.__dict__),
        "types": types,
        "getcwd": os.getcwd,
        "lstat": os.lstat,
        "readlink": os.readlink,
        "get_ident": _thread.get_ident,
        "main_thread": _thread.get_ident(),  # install runs on the kernel's main thread
        **{name: globals()[name] for name in ("BEGIN", "VERDICT", "NOTE", "NOT_COMPARED", "NOTED", "STANDARD_MODULES")},
        **{n: globals()[n] for n in ("FRAME_ATTRIBUTES", "FRAME_CONSUMERS", "FRAME_WRAPPERS", "TRACEBACK_LINES")},
        "get_objects": gc.get_objects,
        "get_referents": gc.get_referents,
        "getrefcount": sys.getrefcount,
        "_make_hook_code": _make_hook.__code__,
        "loaded": sys.modules,  # the import system's own dict (rebinding sys.modules does not change it)
    }
    make = types.FunctionType(_make_hook.__code__, private, "_make_hook")
    hidden = tuple(h.rstrip("/") + "/" for h in hidden)
    # the real functions that set a Python signal handler or make a built-in module anew go to the hook's
    # closures alone; their modules' names are gated from here on
    signals = (_signal.signal, _signal.getsignal, _signal.valid_signals, _signal.default_int_handler)
    tools = (_hashlib.hmac_digest, os.write, sys._getframe, (*signals, _kernels_handler_codes()), _imp.create_builtin)
    hook = make(key, fd, modules, roots, readable, hidden, seed, calls, grader, builtins.__dict__, tools)
    sys.addaudithook(hook)
    _signal.signal, _imp.create_builtin = _gated_signal, _gated_create_builtin


def _make_hook(key, fd, modules, roots, readable, hidden, seed, calls, grader, builtin_names, tools):  # noqa: C901
    """The audit hook, its state in closures only (made with private globals by :func:`install`)."""
    hmac_digest, write, getframe, signals, create_builtin = tools
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
            # the checks' modules and the seal's own: every name, data too; elsewhere, what code is made of
            if (
                module.__name__.startswith(("tutorial.exercises", "tutorial.tools.grading"))
                or module.__name__ in STANDARD_MODULES
                or isinstance(value, (type, types.FunctionType, types.ModuleType, types.BuiltinFunctionType))
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
    for name, value in list(grader.EXPERIMENTS.items()):  # what a judged check has the kernel run, by name
        snapshot.append((name.partition(":")[0], grader.EXPERIMENTS, name, value))
    check_codes = {  # each check's code -> (its module, the module's names it uses)
        id(f.__code__): (f.__code__, m.__name__, uses(f.__code__, m.__dict__), m.__dict__)
        for m in modules
        if m.__name__ in check_modules
        for n, f in m.__dict__.items()
        if n.startswith("check_") and isinstance(f, types.FunctionType)
    }
    grade_code, require_code = grader.grade.__code__, grader.Result.require.__code__
    judged = loaded.get("tutorial.tools.grading.judged")  # noqa: F821 - the kernel's side of the judge, if any
    judged_run = (judged.Judge.run.__code__, judged.__dict__) if judged is not None else (None, None)
    stand_ins = {  # each judged check's stand-in (judged._asking's): name -> (module, the stand-in)
        n: (m, f)
        for m in modules
        if m.__name__ in check_modules
        for n, f in m.__dict__.items()
        if n.startswith("check_") and isinstance(getattr(f, "__wrapped__", None), types.FunctionType)
    }
    # each judged check's name -> (its module, the names the teacher's check and its experiments use)
    judged_scopes = {n: (m.__name__, uses(f.__wrapped__.__code__, m.__dict__)) for n, (m, f) in stand_ins.items()}
    # what the stand-ins hold (the kernel's Judge, the check's name, the teacher's check), and that Judge's own
    # attributes (its socket, its reader, its lock; not its count of runs): an object's, which no snapshot of a
    # module compares
    judge_parts = [(f, tuple(c.cell_contents for c in f.__closure__ or ())) for _, f in stand_ins.values()]
    judges = {id(v): v for _, cells in judge_parts for v in cells if judged is not None and type(v) is judged.Judge}
    judge_attributes = [(j, dict(vars(j))) for j in judges.values()]

    def judge_changed():
        """What differs in the stand-ins' closures and their Judge's attributes since the seal was installed."""
        out = []
        for f, cells in judge_parts:
            now = tuple(c.cell_contents for c in f.__closure__ or ())
            if len(now) != len(cells) or any(a is not b for a, b in zip(now, cells)):
                out.append(f"{f.__name__}'s closure was changed")
        for j, was in judge_attributes:
            now = vars(j)
            if set(now) != set(was) or any(now[k] is not v for k, v in was.items() if k != "_runs"):
                out.append("the kernel's end of the judge was changed")
        return out

    grader_globals = grader.__dict__
    frame_type = type(getframe(0))

    def with_nested(codes):
        """``codes`` and every code object defined inside them (functions, lambdas, comprehensions), at any depth."""
        found, stack = set(), list(codes)
        while stack:
            code = stack.pop()
            found.add(code)
            stack.extend(k for k in code.co_consts if isinstance(k, types.CodeType))
        return found

    hook_codes = with_nested([_make_hook_code])  # noqa: F821 - this function's: the hook's frames, never an answer's
    # the checks' package (checks, grader, their helpers): frames that hold cases and what each expects
    checks_codes = with_nested(
        f.__code__ for _, f, *_ in function_parts if f.__module__.startswith("tutorial.exercises")
    )
    modules_now = [(m.__name__, m) for m in modules]
    frame_holders = (types.TracebackType, types.GeneratorType, types.CoroutineType, types.AsyncGeneratorType)
    result_type = grader.Result
    state = {"checks": 0, "refused": [], "results": {}, "number": "", "judged": ""}
    suspecting = {grader._suspect.__code__}
    seed_code = grader.hidden_random.__code__
    missing = object()

    def changed(check=None, scope=None):
        """What differs from the snapshot; of the check modules, only what ``check`` (a code id) uses, or what
        ``scope`` names: ``(module, names)``, a judged check's (its experiments and what they use)."""
        module, used = scope or (check_codes[check][1:3] if check in check_codes else (None, ()))
        out = [f"{name} was replaced in sys.modules" for name, m in modules_now if loaded.get(name) is not m]  # noqa: F821
        for where, space, name, value in snapshot:
            if where in check_modules and (where != module or name.rpartition(":")[2] not in used):
                continue  # another check's module, or a name this check does not use (an experiment: by its own)
            if space.get(name, missing) is not value:
                out.append(f"the experiment {name} was replaced" if ":" in name else f"{where}.{name} was replaced")
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

    def learner_code(code):
        """Whether ``code`` is an answer's: not the library's, the environment's or Python's own."""
        name = code.co_filename
        return not name.startswith("<frozen ") and not name.startswith(roots)

    def learner(frame):
        return learner_code(frame.f_code)

    def absolute(path):
        """``path`` made absolute and normal here, never by a library function an answer could replace."""
        parts = []
        for part in (path if path.startswith("/") else getcwd() + "/" + path).split("/"):  # noqa: F821
            if part == "..":
                parts = parts[:-1]
            elif part and part != ".":
                parts.append(part)
        return "/" + "/".join(parts)

    def reaches_memory(path):
        """Whether ``path`` is a process's memory (``.../mem``), itself or through symbolic links."""
        for _ in range(10):
            if path.endswith("/mem"):
                return True
            try:
                if lstat(path).st_mode & 0o170000 != 0o120000:  # noqa: F821 - a private global
                    return False
                target = readlink(path)  # noqa: F821 - a private global
            except OSError:
                return False
            path = absolute(target if target.startswith("/") else path.rsplit("/", 1)[0] + "/" + target)
        return True  # a chain of links this long is not a file an answer needs

    def same_source(source, filename):
        """Whether ``source`` (bytes or text) is the file ``filename``'s own source."""
        if filename.startswith("<frozen") or type(source) not in (bytes, str):
            return False  # Python's frozen modules are never compiled again; an AST could be anything
        try:
            with open(filename, "rb") as file:  # noqa: PTH123 - the hook's private builtins
                held = file.read()
        except OSError:
            return False
        return held == (source if type(source) is bytes else source.encode("utf-8"))

    def learner_near(frame, depth=6):
        """Whether answer code called this within ``depth`` frames (through IPython's open(), socket.py, ...)."""
        while frame is not None and depth > 0:
            if learner(frame):
                return True
            frame, depth = frame.f_back, depth - 1
        return False

    def answer_running(frame):
        """Whether an answer's code runs between ``frame`` and the teacher's check below it (or with no check
        below it at all: a thread of the answer's)."""
        while frame is not None:
            if id(frame.f_code) in check_codes:
                return False
            if learner(frame):
                return True
            frame = frame.f_back
        return False

    def named(code, names):
        name = code.co_filename
        return any(name.endswith(end) and code.co_qualname == qualname for end, qualname in names)

    def its_modules(frame):
        """Whether ``frame`` runs with its module's own globals: a function an answer made of the library's code
        (``types.FunctionType``) with globals of its own would pass for the library's, and call the answer's
        names with what the library hands them (``traceback.extract_stack``'s frame)."""
        space = frame.f_globals
        name = dict.get(space, "__name__")
        module = dict.get(loaded, name) if type(name) is str else None  # noqa: F821 - a private global
        return type(module) is types.ModuleType and module.__dict__ is space

    def consumer(frame):
        """Whether the library code that took a frame, past its wrappers, is one of :data:`FRAME_CONSUMERS`, each
        with its own module's globals."""
        while frame is not None and not learner(frame) and named(frame.f_code, FRAME_WRAPPERS):  # noqa: F821
            if not its_modules(frame):
                return False
            frame = frame.f_back
        if frame is None or learner(frame) or not its_modules(frame):
            return False
        if named(frame.f_code, (TRACEBACK_LINES,)):  # noqa: F821 - a private global
            return dict.get(frame.f_locals, "capture_locals") is False  # never an answer's object's __bool__
        return named(frame.f_code, FRAME_CONSUMERS)  # noqa: F821

    def by_an_answer(frame):
        """Whether ``frame``, or the code that called it through ctypes' own Python (``string_at``, ``cast`` wrap
        its C functions), is an answer's."""
        while frame is not None and frame.f_code.co_filename.endswith("/ctypes/__init__.py") and not learner(frame):
            if not its_modules(frame):
                return True
            frame = frame.f_back
        return frame is None or learner(frame)

    def frame_taken(caller):
        """Whether a frame taken by ``caller`` during a check could reach the answer: the answer's own call, or a
        library's for it (not one that keeps the frame to itself)."""
        return learner(caller) or (answer_running(caller) and not consumer(caller))

    paused_kinds = {types.GeneratorType: "gi_code", types.CoroutineType: "cr_code", types.AsyncGeneratorType: "ag_code"}

    def frame_counts(obj):
        """The reference counts of the frame objects ``obj`` (a generator or coroutine) holds, seen from here."""
        return [getrefcount(r) for r in get_referents(obj) if type(r) is frame_type]  # noqa: F821 - private globals

    def calibration():  # a paused generator whose frame only an exception made, as an honest answer's may be
        while True:
            try:
                raise ValueError
            except ValueError:
                pass
            yield

    probe = calibration()
    next(probe)
    kept_alone = max(frame_counts(probe), default=0)  # the count of a frame its generator alone keeps
    probe.close()

    def paused_frames():
        """Whether an answer's paused generator or coroutine has had its frame taken: resumed inside a check, that
        frame's f_back would lead to the check's.  A frame that only Python made (an exception caught inside the
        generator, a warning, a log line) is kept by its generator alone; one the answer took is kept by more (a
        local of the generator's own, a list; frames take no weak references)."""
        for obj in get_objects():  # noqa: F821 - a private global
            attribute = paused_kinds.get(type(obj))
            if attribute is not None and learner_code(getattr(obj, attribute)):
                if any(n > kept_alone for n in frame_counts(obj)):
                    return True
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
        """The exercise whose check is running, the judged check asking the judge (its name), or "" (then the
        grader gives a note to the next check)."""
        return state["number"] if state["checks"] else state["judged"]

    class Refused(Exception):  # noqa: N818 - what act() says to refuse; the hook raises the RuntimeError
        pass

    def refuse(what):
        state["refused"].append(what)
        send(NOTE, "refused", what, here())
        raise Refused(what)

    busy = set()  # the threads inside the hook: what it does itself raises events, which it lets pass
    asking = set()  # the threads inside own_event(): its own frame reads pass

    def own_event():
        """Whether the event this thread raised while inside the hook comes from the hook's own code, not from code
        that ran there unasked: a signal's handler, a finalizer the garbage collector called, an answer's method."""
        me = get_ident()  # noqa: F821 - a private global
        asking.add(me)
        try:
            return getframe(2).f_code in hook_codes  # 0: here, 1: hook, 2: the code that raised it
        except ValueError:
            return False
        finally:
            asking.discard(me)

    def hook(event, args):
        if not (event.startswith("rtt.") or event in WATCHED or event.startswith("ctypes.")):
            return
        if event == "object.__getattr__" and (
            len(args) < 2 or type(args[1]) is not str or args[1] not in FRAME_ATTRIBUTES  # noqa: F821
        ):
            return  # f_code, __code__, ...: the hook's own reads, and nothing it acts on (an odd name: by hand)
        me = get_ident()  # noqa: F821 - a private global
        if me in busy:
            if (me in asking and event == "sys._getframe") or own_event():
                return
            # Let pass, such code could take the hook's frames and read its closures (the key).  No note: the garbage
            # collector runs honest finalizers here too (a warning's frame read), which are refused as quietly.
            raise RuntimeError("the grader's sandbox refused: code run inside the seal's hook")
        busy.add(me)
        why = pending = None
        try:
            pending = act(event, args)
        except Refused as refused:
            why = refused.args[0]
        except Exception:  # noqa: BLE001, S110 - an event raised by hand with odd arguments: nothing to do
            pass
        finally:
            busy.discard(me)
        if pending is not None:
            # A gated real function, run past the guard: what it runs in turn (a pending signal's handler, an
            # attribute of an answer's spec) is watched as any code is.
            function, arguments, out = pending
            made = function(*arguments)
            if function is create_builtin and not a_new_module(made):
                try:
                    refuse("a second _signal or _imp module (its own signal(), set past the seal)")
                except Refused as refused:
                    why = refused.args[0]
            else:
                list.append(out, made)
        if why is not None:  # raised here, its traceback holds no frame of act(); the hook's own is refused
            raise RuntimeError(f"the grader's sandbox refused: {why}")

    def a_new_module(module):
        """Whether ``module``, just made by the real ``_imp.create_builtin``, is neither ``_signal`` nor ``_imp``."""
        name = dict.get(module.__dict__, "__name__") if type(module) is types.ModuleType else None
        return type(name) is str and name not in ("_signal", "_imp")

    def leads_to(frame, codes):
        """Whether ``frame`` is, or is called by, code of ``codes`` (the checks', the hook's)."""
        while frame is not None:
            if frame.f_code in codes:
                return True
            frame = frame.f_back
        return False

    def forget_checks_frames():
        """Clear every frame of the checks' code that has ended (its locals: cases, what each expects, the seed's
        random source): a frame made during a check (a traceback's, of an exception an answer raised and kept)
        outlives it, and ``f_back`` from it, which Python does not audit, leads to the check's frames."""
        state["frames_left"] = False  # until the next check: no frame of the checks' is made outside one
        for obj in get_objects():  # noqa: F821 - a private global
            if type(obj) is frame_type and obj.f_code in checks_codes:
                try:
                    frame_type.clear(obj)
                except RuntimeError:
                    pass  # still running (a thread of a check's): not the answer's to read either

    def ours(frame):
        """Whether ``frame`` runs with the grader module's real globals (not a copy an answer made)."""
        return frame is not None and frame.f_globals is grader_globals

    def act(event, args):  # noqa: C901 - one branch per event
        try:
            caller = getframe(2)  # 0: act, 1: hook, 2: the code that raised the event
        except ValueError:  # no Python code at all: a C callable an answer's raw _thread runs
            if event in FRAMELESS_REFUSED or event.startswith("ctypes."):
                refuse(f"{event} from a thread with no Python code")
            return
        elsewhere = get_ident() != main_thread  # noqa: F821 - a private global
        if elsewhere and event in OTHER_THREADS_REFUSED:
            # Another thread's stack may hold no answer frame even when the answer started it (its target a C
            # callable: list.extend fed a map of gc.get_objects); nothing the kernel's or a check's threads do
            # needs these
            refuse(f"{event} in a thread other than the kernel's main thread")
        if event == "rtt.check_begin":
            if caller.f_code is grade_code and ours(caller):
                state["checks"] += 1
                state["refused"] = []
                state["frames_left"] = True
                state["number"] = number_of(args[0])
                state["begin_changes"] = changed(genuine_check(caller.f_back))
                if paused_frames():
                    state["begin_changes"].append("an answer's paused generator had its frame taken")
                if answers_handlers():
                    state["begin_changes"].append("a signal handler not the kernel's")
                send(BEGIN, number_of(args[0]))
        elif event == "rtt.judged":  # judged.Judge.run: a check the judge runs begins or ends asking this kernel
            if caller.f_code is judged_run[0] and caller.f_globals is judged_run[1] and type(args[1]) is str:
                state["judged"] = args[1] if args[0] == "begin" else ""
                # the experiments it runs here are the check module's own functions, compared with what they use
                reasons = changed(scope=judged_scopes.get(args[1], ("", ()))) + judge_changed()
                reasons += ["a signal handler not the kernel's"] if answers_handlers() else []
                if reasons:
                    send(NOTE, "tampering", "; ".join(dict.fromkeys(reasons[:3])), args[1])
        elif event == "rtt.check_end":
            if caller.f_code is grade_code and ours(caller):
                state["checks"] = max(0, state["checks"] - 1)  # also after an interrupt (a cell's timeout)
        elif event == "rtt.result":
            result = args[0]
            if caller.f_code is grade_code and ours(caller) and type(result) is result_type:
                check = genuine_check(caller.f_back)
                reasons = list(state.get("begin_changes", [])) + changed(check) + list(state["refused"])
                if answers_handlers():
                    reasons.append("a signal handler not the kernel's")
                if check is None:
                    reasons.append("grade() was not called by one of the teacher's checks")
                fields = result.__dict__
                passed = dict.get(fields, "passed") is True  # an identity: no method of an answer's object
                record = (result, number_of(dict.get(fields, "exercise")), passed, reasons, check)
                state["results"][id(result)] = record
        elif event == "rtt.verdict":
            result = args[0]
            record = state["results"].get(id(result))
            if caller.f_code is not require_code or not ours(caller) or record is None:
                exercise = dict.get(result.__dict__, "exercise") if type(result) is result_type else None
                send(NOTE, "tampering", "a verdict not made by the teacher's check and require()", number_of(exercise))
                return
            _, number, passed, reasons, check = record
            statement = caller.f_back
            reasons = list(reasons) + changed(check)
            if statement is None or not same_call(statement.f_code):
                reasons.append("require() was not called by the test cell's statement")
            reasons = list(dict.fromkeys(reasons))
            send(VERDICT, number, int(passed), int(not reasons), "; ".join(reasons[:3]))
        elif event == "rtt.seed":
            check = genuine_check(caller.f_back)
            if seed and caller.f_code is seed_code and ours(caller) and check is not None:
                if type(args[0]) is list and not changed(check):  # never to a Random an answer replaced
                    list.append(args[0], seed)
        elif event == "rtt.suspect":
            if caller.f_code in suspecting and ours(caller) and type(args[0]) is str:
                send(NOTE, "tampering", "an answer returned " + args[0], here())
        elif event == "rtt.signal":  # signal.signal(), through _gated_signal
            number, handler, out = args
            if type(number) is not int or type(out) is not list:
                refuse("a signal handler set with odd arguments")
            if not kernels_handler(handler):
                refuse(f"a signal handler of the answer's (signal {number}): Python hands it the running frame")
            return set_signal, (number, handler), out
        elif event == "rtt.create_builtin":  # _imp.create_builtin(), through _gated_create_builtin
            spec, out = args
            if type(out) is not list:
                refuse("a built-in module made with odd arguments")
            return create_builtin, (spec,), out
        elif event == "sys.addaudithook":
            refuse(event)
        elif event in ("sys._current_frames", "sys.settrace", "sys.setprofile"):
            # a way to the frames of this hook (another thread's, a tracer's): the answer's own call, or a thread
            # started with the answer's tracer (threading.settrace, set by the thread's bootstrap)
            hooks = [dict.get(caller.f_globals, n) for n in ("_trace_hook", "_profile_hook")]
            if learner_near(caller) or any(type(f) is types.FunctionType and learner_code(f.__code__) for f in hooks):
                refuse(event)
        elif event in ("object.__setattr__", "object.__delattr__"):
            if id(args[0]) in trusted:
                attribute = args[1] if type(args[1]) is str else "?"
                refuse(f"changing {getattr(args[0], '__qualname__', '?')}.{attribute}")
        elif event in ("compile", "code.__new__"):
            filename = args[1] if type(args[1]) is str else ""
            if filename.startswith(roots) or filename.startswith("<frozen"):
                # Library code is known by its file's name: code compiled under that name is the library's only
                # when it is that file's source (the import system's compile of it), whoever asked for it
                if event == "code.__new__":
                    forged = learner_near(caller)
                else:
                    forged = not same_source(args[0], filename)
                if forged:
                    refuse(f"code claiming to be the library's ({filename})")
        elif event == "open":
            path = args[0]
            if type(path) is not str:
                return  # a file descriptor, or bytes: not an answer's way to a path here
            path = absolute(path)
            if reaches_memory(path):
                refuse(f"opening {path}")
            allowed = ALLOWED + roots + readable + (getcwd() + "/",)  # noqa: F821 - a private global
            outside = not path.startswith(allowed) or (path.startswith(hidden) and not path.startswith(roots))
            if outside and learner_near(caller):
                send(NOTE, "outside", f"opened {path}", here())
        elif event in ("os.symlink", "os.link") and type(args[0]) is str and "/proc/" in absolute(args[0]):
            refuse(f"a link to {args[0]}")
        elif event.startswith("ctypes.") and by_an_answer(caller):
            refuse(event)  # raw memory: the seal's key, or any object
        elif event in ("gc.get_objects", "gc.get_referrers", "gc.get_referents") and learner_near(caller):
            refuse(event)  # every object, the hook's closures among them
        elif event == "object.__getattr__" and type(args[0]) in frame_holders and args[1] in FRAME_ATTRIBUTES:
            frame = getattr(args[0], args[1], None)  # read here, where the hook lets its own events pass
            if type(frame) is frame_type and leads_to(frame, hook_codes):
                refuse("reading the grader's own frames")  # a frame called by the hook's leads there too
            if state["checks"] > 0 and frame_taken(caller):
                refuse(f"reading {args[1]} during a check")
            # f_back of an answer's own frame, kept from a check, leads to the check's; another thread's stack may
            # hold no answer frame even when the answer started it
            if state["checks"] == 0 and state.get("frames_left") and (elsewhere or learner_near(caller)):
                forget_checks_frames()
            if state["checks"] > 0 and elsewhere and type(frame) is frame_type and leads_to(frame, checks_codes):
                refuse(f"reading {args[1]} of a check's from another thread")
        elif event in NOTED:
            if learner_near(caller):
                send(NOTE, "network" if event.startswith("socket") else "processes", event, here())
        elif event == "sys._getframe" and type(args[0]) is frame_type:
            # Code the hook ran (a signal's handler, at any of its lines) must not walk down to its frames.  No
            # note: an honest finalizer the garbage collector runs there (a log line) is refused as quietly.
            if leads_to(args[0], hook_codes):
                raise Refused("reading the grader's own frames")
            if state["checks"] > 0 and frame_taken(caller):
                refuse("reading frames during a check")  # the answer's own call, inspect.currentframe()'s, ...

    set_signal, get_signal, valid_signals, default_int_handler, handler_codes = signals
    handlers_before = {id(h): h for h in map(get_signal, valid_signals()) if h is not None and type(h) is not int}
    handlers_before[id(default_int_handler)] = default_int_handler  # kept alive: an id is never reused

    def kernels_handler(handler):
        """Whether ``handler`` is SIG_DFL, SIG_IGN, none (a C handler), one set before any answer ran, or a function
        of ipykernel's ``handle_sigint`` code itself (by identity: its file's name can be forged, a partial's
        arguments would move the frame to another parameter)."""
        if handler is None or type(handler) is int or id(handler) in handlers_before:
            return True
        if type(handler) is not types.FunctionType:
            return False
        code = handler.__code__
        return any(code is k for k in handler_codes)

    def answers_handlers():
        """The signals whose Python handler is not the kernel's (set past the gate, which nothing should allow)."""
        return [n for n in valid_signals() if not kernels_handler(get_signal(n))]

    def genuine_check(frame):
        """The id of the teacher's check whose code ``frame`` runs with its module's real globals, or None."""
        if frame is None or id(frame.f_code) not in check_codes:
            return None
        return id(frame.f_code) if frame.f_globals is check_codes[id(frame.f_code)][3] else None

    OTHER_THREADS_REFUSED = {"gc.get_objects", "gc.get_referrers", "gc.get_referents", "sys._current_frames"}
    FRAMELESS_REFUSED = OTHER_THREADS_REFUSED | {
        "object.__getattr__",
        "object.__setattr__",
        "object.__delattr__",
        "sys.settrace",
        "sys.setprofile",
        "sys.addaudithook",
    }
    WATCHED = (
        NOTED
        | {"sys.addaudithook", "sys._current_frames", "sys.settrace", "sys.setprofile"}
        | {"gc.get_objects", "gc.get_referrers", "gc.get_referents"}
        | {"object.__setattr__", "object.__delattr__", "compile", "code.__new__", "open"}
        | {"os.symlink", "os.link"}
        | {"sys._getframe", "object.__getattr__"}
    )
    ALLOWED = ("/tmp/", "/dev/", "/proc/self/", "/sys/", "/etc/", "/usr/", "/lib", "/run/")
    return hook
