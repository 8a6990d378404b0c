#!/usr/bin/env bash
# Installs Debian's Chromium for the browser tests when it is missing (they open the viewer's meshcat page,
# JupyterLab and the book in headless Chromium). Needs root or sudo.
exec bash "$(dirname "$0")/ensure-debian-package.sh" chromium chromium "the browser tests"
