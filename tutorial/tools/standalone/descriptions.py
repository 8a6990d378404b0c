"""A viewer whose model is a robot description topic: wait for the URDF and load it as a MuJoCo model.

``project/step3_description.yaml`` names ``/Tank/robot_description`` instead
of a model file; :func:`receive_descriptions` fills such models in before
the App builds its world.  :class:`tutorial.tools.standalone.app.StandaloneApp`
(what ``rtt-run`` runs) calls it: the lessons' own :class:`tutorial.app.app.App`
refuses such models, so the URDF tools stay out of the lessons' library
(``scripts/library_size.py``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

from tutorial.core.project import Project

DESCRIPTION_TIMEOUT = 10.0  # s a viewer waits for a robot description it takes its model from


def receive_descriptions(
    project: Project, node, timeout: float, output: Callable[[dict], None], stopped: Callable[[], bool] | None = None
) -> Project:
    """``project`` with each model that names a description topic taken from the URDF published there.

    Waits up to ``timeout`` s for each on ``node`` (the publisher keeps it,
    transient local: a simulation already running answers at once), and
    says where the model came from, one record to ``output`` per model.  A
    description that cannot be drawn (not a URDF, a joint without its
    parent, a model MuJoCo cannot compile) is said in a warning record, and
    the wait goes on for a corrected one, with no deadline, as a robot's
    ``robot_state_publisher`` publishes a fixed file again.  ``stopped``
    (the App's stop request, Ctrl-C in ``rtt-run``) ends any wait.  The App's
    owner thread calls it, before the node's spin thread starts.

    Raises:
        tutorial.interfaces.robot_description.DescriptionError: none came
            within ``timeout`` s.
        KeyboardInterrupt: ``stopped`` said True while it waited.
    """
    waiting = [m for m in project.models if m.description is not None and m.text is None]
    if not waiting:
        return project
    # imported here, so opening an App whose models are files never loads the URDF tools
    from tutorial.interfaces.robot_description import receive_robot_description
    from tutorial.tools.urdf.mujoco_load import load_description

    models = list(project.models)
    fqn = node.get_fully_qualified_name()
    for entry in waiting:

        def refused(exc, entry=entry):
            message = f"{exc}: waiting for a corrected description on {entry.description}"
            output({"event": "warning", "node": fqn, "body": entry.name, "message": message})

        prepared, tree = receive_robot_description(
            node,
            entry.description,
            timeout,
            use=lambda urdf, entry=entry: load_description(urdf, entry.description),
            on_refused=refused,
            stopped=stopped,
        )
        models[models.index(entry)] = dataclasses.replace(entry, text=prepared.text)
        notes = [*prepared.changed]
        if prepared.left_out:
            notes.append(f"{len(prepared.left_out)} mesh visuals left out")
        # a mimic joint moves with its leader: a joint state need not carry it (the status line counts the others);
        # one whose leader is not in the file moves by its own position, as robot_state_publisher moves it
        leaders = {j.name for j in tree.moving}
        mimic = sum(j.mimic is not None and j.mimic[0] in leaders for j in tree.moving)
        following = f", {mimic} of them following another (mimic)" if mimic else ""
        for line in prepared.left_out:  # which mesh, and why: the rest of the robot is drawn
            output({"event": "warning", "node": fqn, "body": entry.name, "message": f"{entry.description}: {line}"})
        output(
            {
                "event": "description",
                "node": fqn,
                "body": entry.name,
                "topic": entry.description,
                "links": len(tree.links),
                "moving_joints": [j.name for j in tree.moving],
                "changed": list(prepared.changed),
                "line": f"[{fqn}] {entry.name}: no model file of its own: drawing the robot description "
                f"on {entry.description} (robot {tree.name}, {len(tree.links)} links, "
                f"{len(tree.moving)} moving joints{following}{''.join(f'; {n}' for n in notes)})",
            }
        )
    return dataclasses.replace(project, models=models)
