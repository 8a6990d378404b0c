#!/bin/sh
# The learner image's entry point (under tini): the learner's home gets what is missing of the notebooks and
# the project's files (course/learner_home.py: a volume mounted over /home/jovyan starts empty on Kubernetes;
# a learner's own work is never overwritten), then the command runs (jupyterhub-singleuser by default).
python /opt/rtt/course/learner_home.py "$HOME" > /dev/null || echo "start-learner: the notebooks could not be copied into $HOME" >&2
exec "$@"
