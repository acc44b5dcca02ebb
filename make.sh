#!/bin/sh
# `make`, installed first when this machine has none (a fresh Debian has no make; the
# Makefile then installs everything else): sh make.sh run | test | bench | ...
set -e
cd "$(dirname "$0")"
if ! command -v make >/dev/null 2>&1; then
    # a dry run (-n, in a cluster such as -sn, --dry-run / --just-print / --recon and their
    # abbreviations, or n in MAKEFLAGS' flag letters) installs nothing (re-check review 45)
    flags=${MAKEFLAGS%% *}
    case "$flags" in -*|'') ;; *n*) set -- -n "$@";; esac
    for a in "$@"; do
        case "$a" in
            --dry*|--just*|--rec*) dry=$a;;
            --*|-*/*|-*=*) ;;  # a long option, or an option with a path or value (-I/usr/n)
            -*n*) dry=$a;;
        esac
        if [ -n "${dry:-}" ]; then
            echo "make.sh: make is not installed; a dry run ($dry) installs nothing" >&2
            exit 2
        fi
    done
    if [ "$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi
    $SUDO apt-get update -qq
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq make
fi
exec make "$@"
