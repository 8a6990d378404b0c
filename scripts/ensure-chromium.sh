#!/usr/bin/env bash
# Installs Debian's Chromium for the browser test when it is missing (the test
# opens the viewer's meshcat page in headless Chromium). Needs root or sudo.
set -euo pipefail
if command -v chromium >/dev/null 2>&1; then
  exit 0
fi
SUDO=""
if [ "$(id -u)" != "0" ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "ensure-chromium: chromium is missing and we are not root; install it (apt-get install chromium)" >&2
    exit 1
  fi
fi
echo "ensure-chromium: installing Debian's chromium for the browser test"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium >/dev/null
command -v chromium
