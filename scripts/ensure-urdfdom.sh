#!/usr/bin/env bash
# Installs Debian's urdfdom tools (check_urdf, ROS's own URDF parser) when missing: make test-robots asks it
# which of example-robot-data's files a ROS program would accept. Needs root or sudo.
set -euo pipefail
if command -v check_urdf >/dev/null 2>&1; then
  exit 0
fi
SUDO=""
if [ "$(id -u)" != "0" ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "ensure-urdfdom: check_urdf is missing and we are not root; install it (apt-get install liburdfdom-tools)" >&2
    exit 1
  fi
fi
echo "ensure-urdfdom: installing Debian's liburdfdom-tools (check_urdf)"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq liburdfdom-tools >/dev/null
command -v check_urdf
