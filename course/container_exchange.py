"""nbgrader's exchange for a class on containers: each learner's container hands in to a folder of its own.

In containers every learner is the same user inside (``jovyan``, uid 1000), so a shared ``inbound/`` would let
one learner read, or replace, another's work, and a submission's owner is a uid of no account here, not a name
(``course/submissions.py`` reads a learner's name from their Unix user where learners are users).
Instead each learner's container is given, at the exchange's own paths (so the hub's ``nbgrader_config.py``
for learners serves here too):

- ``outbound/`` (the released assignments) and ``feedback/``, read only;
- as ``inbound/``, the host's ``inbound-by-learner/NAME/``, NAME being the hub's name for that learner, which
  the learner cannot change;
- all under an exchange root of the learner's own (``container-roots/NAME/``), as nbgrader asks for one its
  user can write.

``make grade`` stages those with the rest, refusing a submission whose name is not its folder's
(``course/submissions.py``).  The hub's thread calls :func:`give_learner_their_exchange` (the pre-spawn hook).
The folders are given to this machine's uid for that learner's ``jovyan``: each container runs in a user
namespace of its own (``course/jupyterhub_containers_config.py``), so no account of this machine, and no other
learner, owns them.
"""

from __future__ import annotations

import os
from pathlib import Path

COURSE_ID = "ros-tank-tutorial"
BY_LEARNER = "inbound-by-learner"  # course/submissions.py reads it too
ROOTS = "container-roots"  # each learner's exchange root, under which the folders above are mounted
JOVYAN = 1000  # the image's user (course/containers/Containerfile)


def give_learner_their_exchange(spawner, exchange: Path, learner_config: Path, owner: int = JOVYAN) -> None:
    """Add to ``spawner.volumes`` the exchange as ``spawner.user.name`` sees it, making their folders, owned
    by ``owner``: this machine's uid for the image's user in that learner's container (its user namespace)."""
    course = exchange / COURSE_ID
    name = spawner.user.name
    (course / "outbound").mkdir(mode=0o755, parents=True, exist_ok=True)
    course.chmod(0o755)  # the teacher's alone to write, whatever the hub's umask (course/submissions.py checks)
    (course / "feedback").mkdir(exist_ok=True)
    (course / "feedback").chmod(0o711)  # as nbgrader makes it: a learner reads their own feedback, lists none
    (course / BY_LEARNER).mkdir(mode=0o711, exist_ok=True)  # entered, never listed, by the containers' user
    own = course / BY_LEARNER / name
    # nbgrader asks for an exchange root its user can write: one of the learner's own, under the rest
    (course / ROOTS).mkdir(mode=0o711, exist_ok=True)
    root = course / ROOTS / name
    for folder in (own, root):
        folder.mkdir(mode=0o700, exist_ok=True)
        os.chown(folder, owner, owner)
    spawner.volumes = {
        **spawner.volumes,
        str(learner_config / "nbgrader_config.py"): {"bind": "/etc/jupyter/nbgrader_config.py", "mode": "ro"},
        str(root): {"bind": str(exchange), "mode": "rw"},
        str(course / "outbound"): {"bind": str(course / "outbound"), "mode": "ro"},
        str(course / "feedback"): {"bind": str(course / "feedback"), "mode": "ro"},
        str(own): {"bind": str(course / "inbound"), "mode": "rw"},
    }
