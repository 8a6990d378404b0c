#!/usr/bin/env bash
# Installs Debian's nftables for the network tier when it is missing (its tests put packet loss and
# partitions on the links between their own hosts, network namespaces, with `nft`).  Needs root:
# without it nothing is installed and the network tier skips, saying why (it needs root anyway).
set -euo pipefail
if command -v nft >/dev/null 2>&1; then
  exit 0
fi
if [ "$(id -u)" != "0" ]; then
  echo "ensure-nftables: nft is missing and we are not root: the network tier will skip (it needs root)" >&2
  exit 0
fi
echo "ensure-nftables: installing Debian's nftables for the network tier"
apt-get update -qq
DEBIAN_FRONTEND=noninteractive apt-get install -y -qq nftables >/dev/null
command -v nft
