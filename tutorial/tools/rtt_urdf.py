"""``rtt-urdf``: write a URDF of a MuJoCo model (or of a body of a project), for RViz2 and Foxglove.

    rtt-urdf model/tank.xml -o tank.urdf                   # the robot is named after the model: Tank
    rtt-urdf project/step2.yaml --body Tank -o tank.urdf   # a body of a project, named as there
    rtt-urdf model/arm6.xml --body Arm -o arm.urdf --mesh-uri file

Mesh geoms become STL files in ``<FILE stem>_meshes/`` beside the URDF.  What
is mapped, and what is approximated or left out, is in
:mod:`tutorial.tools.urdf.export` and in the file's opening comment.

Exit status: 0 written; 2 a bad command line, a model that does not load, a
body that is not in the project, or a file that cannot be written (one line
on stderr says which).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

PROG = "rtt-urdf"


def _fail(text: str) -> int:
    print(f"{PROG}: {text}", file=sys.stderr, flush=True)
    return 2


def main(argv: list[str] | None = None) -> int:
    """``rtt-urdf``: parse the command line, write the URDF; the exit status (main thread)."""
    p = argparse.ArgumentParser(prog=PROG, description="Write a URDF of a MuJoCo model's body.")
    p.add_argument("model", metavar="MODEL", help="an MJCF model file, or a project file (.yaml) with --body")
    p.add_argument(
        "--body", metavar="NAME", help="the body's name (its topics are /NAME/...); in a project, which body"
    )
    p.add_argument("-o", "--output", required=True, metavar="FILE.urdf", help="the URDF to write")
    p.add_argument(
        "--mesh-uri",
        choices=["relative", "file"],
        default="relative",
        help="name mesh files relative to the URDF (default; yourdfpy, MuJoCo) or as file:// URIs (RViz2, Foxglove)",
    )
    args = p.parse_args(sys.argv[1:] if argv is None else argv)
    from tutorial.core.project import ProjectError
    from tutorial.tools.urdf.export import export_model_file

    model = Path(args.model)
    name = args.body
    try:
        if model.suffix in (".yaml", ".yml"):
            from tutorial.core.project import load_project

            project = load_project(model)
            entries = [m for m in project.models if m.file is not None]
            if name is None:
                if len(entries) != 1:
                    return _fail(f"{model}: name the body with --body, one of {[m.name for m in entries]}")
                name = entries[0].name
            entry = next((m for m in entries if m.name == name), None)
            if entry is None:
                return _fail(f"{model}: no body {name!r} with a model file; it has {[m.name for m in entries]}")
            model = entry.file
        if not model.is_file():
            return _fail(f"{model}: no such model file")
        _, urdf = export_model_file(model, name)
        written = urdf.write(args.output, mesh_uri=args.mesh_uri, source=model.name)
    except (ProjectError, ValueError) as exc:
        return _fail(str(exc))
    except OSError as exc:
        return _fail(f"cannot write {args.output}: {exc.strerror or exc}")
    links, joints = len(urdf.links), len(urdf.joints)
    print(
        f"wrote {written[0]}: robot {urdf.name}, {links} links, {joints} joints "
        f"({len(urdf.moving_joints)} moving: {', '.join(urdf.moving_joints) or 'none'}), root link {urdf.root_link}"
        + (f", {len(written) - 1} mesh files" if len(written) > 1 else ""),
        flush=True,
    )
    for note in urdf.notes:
        print(f"  approximated or left out: {note}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
