#!/bin/sh
# `make`, installed first when this machine has none (a fresh Debian has no make; the
# Makefile then installs everything else): sh make.sh run | test | bench | ...
# make's own options are passed through unread: a dry run (-n) installs make too, as make is
# what prints the dry run (reading make's options here refused real runs — -Iinclude,
# MAKEFLAGS=DESTDIR=… — and missed dry runs; re-check review 46).
set -e
cd "$(dirname "$0")"
if ! command -v make >/dev/null 2>&1; then
    echo "make.sh: make is not installed; installing Debian's make first" >&2
    if [ "$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi
    $SUDO apt-get update -qq
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq make
fi
exec make "$@"
