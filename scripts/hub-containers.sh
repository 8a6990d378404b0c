#!/usr/bin/env bash
# make hub-containers: the class's JupyterHub with each learner's server a container of the learner image
# (course/jupyterhub_containers_config.py), through podman's Docker-compatible API.  As root.  Everything it
# makes goes when it stops: podman's API service, the containers' network and the container holding it up;
# the learners' home volumes (rtt-home-<name>) stay, as a class's do.  netavark turns IP forwarding on for its
# networks: it is put back as it was.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "$(id -u)" != "0" ]; then
  echo "hub-containers: podman here runs as root: run make hub-containers as root (make hub needs no container)" >&2
  exit 1
fi
bash scripts/ensure-podman.sh
export CONTAINERS_CONF="$PWD/course/containers/containers.conf"
state="${RTT_HUB_STATE:-$PWD/course/.hub-containers}"
network="${RTT_HUB_CONTAINER_NETWORK:-rtt-learners}"
image="${RTT_HUB_IMAGE:-localhost/ros-tank-tutorial:learner}"
mkdir -p "$state"
forward=$(cat /proc/sys/net/ipv4/ip_forward)
socket="$state/podman.sock"
podman system service --time=0 "unix://$socket" &
service=$!
made_network=0
cleanup() {
  podman rm --force --time 0 "$network-keeper" >/dev/null 2>&1 || true
  if [ "$made_network" = 1 ]; then podman network rm --force "$network" >/dev/null 2>&1 || true; fi
  kill "$service" 2>/dev/null || true
  echo "$forward" > /proc/sys/net/ipv4/ip_forward
}
trap cleanup EXIT
if ! podman network exists "$network"; then
  podman network create --internal "$network" >/dev/null  # no route beyond this machine
  made_network=1
fi
# The network's bridge, and the hub's address on it, exist while a container is on it: one holds it up.
podman run --detach --rm --name "$network-keeper" --network "$network" "$image" sleep infinity >/dev/null
gateway=$(podman network inspect "$network" --format '{{range .Subnets}}{{.Gateway}}{{end}}')
if [ -z "$gateway" ]; then
  echo "hub-containers: network $network has no gateway address for the hub's API to listen on" >&2
  exit 1
fi
for _ in $(seq 100); do [ -S "$socket" ] && break; sleep 0.1; done
DOCKER_HOST="unix://$socket" RTT_HUB_STATE="$state" RTT_HUB_CONTAINER_GATEWAY="$gateway" \
  RTT_HUB_CONTAINER_NETWORK="$network" RTT_HUB_IMAGE="$image" RTT_HUB_PER_LEARNER_NETWORK=1 \
  "${RTT_HUB_JUPYTERHUB:-.venv/bin/jupyterhub}" -f course/jupyterhub_containers_config.py
