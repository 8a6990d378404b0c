#!/usr/bin/env bash
# ensure-debian-package.sh COMMAND PACKAGE WHAT-FOR: installs Debian's PACKAGE when COMMAND is missing
# (chromium for the browser tests, liburdfdom-tools' check_urdf for make test-robots). Needs root or sudo.
set -euo pipefail
command="$1" package="$2" purpose="$3"
if command -v "$command" >/dev/null 2>&1; then
  exit 0
fi
SUDO=""
if [ "$(id -u)" != "0" ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "ensure: $command is missing and we are not root; install it (apt-get install $package)" >&2
    exit 1
  fi
fi
echo "ensure: installing Debian's $package for $purpose"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "$package" >/dev/null
command -v "$command"
