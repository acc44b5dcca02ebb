#!/bin/sh
# `make`, installed first when this machine has none (a fresh Debian has no make; the
# Makefile then installs everything else): sh make.sh run | test | bench | ...
set -e
cd "$(dirname "$0")"
if ! command -v make >/dev/null 2>&1; then
    for a in "$@"; do
        case "$a" in
            -n|--dry-run|--just-print|--recon)
                echo "make.sh: make is not installed; a dry run ($a) installs nothing" >&2
                exit 2;;
        esac
    done
    if [ "$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi
    $SUDO apt-get update -qq
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq make
fi
exec make "$@"
