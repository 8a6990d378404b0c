#!/usr/bin/env bash
# Installs Debian's podman (with runc, and mmdebstrap for a base image) for the learner image when missing,
# and makes the base image localhost/rtt-base:bookworm when podman has none: no image registry may be
# reachable, so it is a Debian 12 root file system made by mmdebstrap from Debian's mirror (minbase, with
# ca-certificates) and imported.  Needs root: without it nothing is done and the container tier skips.
# podman reads the project's own settings (CONTAINERS_CONF=course/containers/containers.conf).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "$(id -u)" != "0" ]; then
  echo "ensure-podman: not root: the learner image is not built here (make test-containers skips)" >&2
  exit 0
fi
if ! command -v podman >/dev/null 2>&1 || ! command -v runc >/dev/null 2>&1 || ! command -v mmdebstrap >/dev/null 2>&1; then
  echo "ensure-podman: installing Debian's podman, runc and mmdebstrap"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq podman runc mmdebstrap >/dev/null
fi
export CONTAINERS_CONF="$PWD/course/containers/containers.conf"
if ! podman image exists localhost/rtt-base:bookworm; then
  mirror=$(sed -n 's/^URIs: *//p' /etc/apt/sources.list.d/debian.sources 2>/dev/null | head -1)
  tar=$(mktemp --suffix=.tar)
  trap 'rm -f "$tar"' EXIT
  echo "ensure-podman: making the base image localhost/rtt-base:bookworm with mmdebstrap"
  mmdebstrap --quiet --variant=minbase --include=ca-certificates bookworm "$tar" "${mirror:-http://deb.debian.org/debian}"
  podman import --quiet "$tar" localhost/rtt-base:bookworm >/dev/null
fi
