"""The set-up commands of the README (``sh make.sh run`` / ``test``) on a machine that lacks
what they need: ``make.sh`` installs make, the Makefile's first step the Debian packages that
building pycddlib and the virtualenv take (docs review 45: a fresh Debian has no make, no C
compiler, no Python headers and no ensurepip; pycddlib has no Linux wheel). Run with stub
commands on a PATH of their own: nothing is installed."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _stubs(tmp_path: Path, scripts: dict[str, str], real: tuple[str, ...]) -> Path:
    """A folder of stub commands (``scripts``: name → shell body) and links to the ``real``
    commands named; it is the whole PATH of the run."""
    bin_ = tmp_path / "bin"
    bin_.mkdir()
    for name, body in scripts.items():
        f = bin_ / name
        f.write_text(f"#!/bin/sh\n{body}\n")
        f.chmod(0o755)
    for name in real:
        where = shutil.which(name)
        assert where is not None, name
        (bin_ / name).symlink_to(where)
    return bin_


@pytest.mark.skipif(shutil.which("make") is None, reason="needs make for the Makefile run")
def test_the_first_step_installs_compiler_headers_and_venv_when_missing(tmp_path: Path) -> None:
    """No cc on PATH, a Python without headers or ensurepip, libcdd-dev not installed: the
    one apt-get install names every package; with all present, apt-get is not run."""
    log = tmp_path / "apt.log"
    venv = tmp_path / "venv"
    # `python -m venv [--clear] DIR` makes DIR; every other use fails (no headers, no ensurepip)
    python = 'case "$1" in -m) for a; do d=$a; done; mkdir -p "$d";; *) exit 1;; esac'
    bin_ = _stubs(
        tmp_path,
        {
            "dpkg": "exit 1",
            "apt-get": f'echo "$@" >> {log}',
            "python": python,
            "sudo": 'exec "$@"',
        },
        ("id", "touch", "mkdir", "env"),
    )
    env = {"PATH": str(bin_), "HOME": str(tmp_path)}
    make = shutil.which("make")
    assert make is not None
    args = [make, "-s", "-C", str(ROOT), f"VENV={venv}", f"PYTHON={bin_ / 'python'}"]
    r = subprocess.run([*args, f"{venv}/.debs"], env=env, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    lines = log.read_text().splitlines()
    assert lines[0] == "update -qq", lines
    assert lines[1].split()[-5:] == [
        "libcdd-dev",
        "libgmp-dev",
        "build-essential",
        "python3-dev",
        "python3-venv",
    ], lines
    assert (venv / ".debs").exists()
    # everything present (dpkg knows the packages, cc exists, the Python has both): no apt
    (venv / ".debs").unlink()
    log.unlink()
    (bin_ / "dpkg").write_text("#!/bin/sh\nexit 0\n")
    (bin_ / "cc").write_text("#!/bin/sh\nexit 0\n")
    (bin_ / "cc").chmod(0o755)
    (bin_ / "python").write_text(
        '#!/bin/sh\ncase "$1" in -m) for a; do d=$a; done; mkdir -p "$d";; *) exit 0;; esac\n'
    )
    r = subprocess.run([*args, f"{venv}/.debs"], env=env, capture_output=True, text=True)
    assert r.returncode == 0 and not log.exists(), r.stderr


def test_make_sh_installs_make_when_missing_then_runs_it(tmp_path: Path) -> None:
    """``sh make.sh test`` with no make on PATH: apt-get installs make (the stub puts one on
    PATH), then make runs with the arguments given; with make present, no apt-get."""
    log = tmp_path / "calls.log"
    bin_ = _stubs(
        tmp_path,
        {
            "apt-get": (
                f'echo "apt-get $*" >> {log}\n'
                f'[ "$1" = install ] && printf \'#!/bin/sh\\necho "make $*" >> {log}\\n\' '
                f"> {tmp_path}/bin/make && chmod +x {tmp_path}/bin/make\nexit 0"
            ),
            "sudo": 'exec "$@"',
        },
        ("id", "env", "dirname", "printf", "chmod"),
    )
    env = {"PATH": str(bin_), "HOME": str(tmp_path)}
    sh = shutil.which("sh")
    assert sh is not None
    r = subprocess.run([sh, str(ROOT / "make.sh"), "test"], env=env, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    calls = log.read_text().splitlines()
    assert calls[0] == "apt-get update -qq" and calls[1].startswith("apt-get install"), calls
    assert calls[1].split()[-1] == "make" and calls[2] == "make test", calls
    log.unlink()
    r = subprocess.run([sh, str(ROOT / "make.sh"), "run"], env=env, capture_output=True, text=True)
    assert r.returncode == 0 and log.read_text().splitlines() == ["make run"], r.stderr
    assert os.access(ROOT / "make.sh", os.R_OK)


@pytest.mark.skipif(shutil.which("make") is None, reason="needs make for the Makefile run")
def test_a_virtualenv_without_pip_is_made_again(tmp_path: Path) -> None:
    """A .venv left without pip (made before python3-venv was installed: ensurepip failed)
    was kept by ``[ -d .venv ]`` and the next step failed, "No module named pip" (re-check
    review 45): it is made again with --clear; a working one is left alone."""
    log = tmp_path / "venv.log"
    venv = tmp_path / "venv"
    (venv / "bin").mkdir(parents=True)
    bin_ = _stubs(
        tmp_path,
        {
            "dpkg": "exit 0",
            "cc": "exit 0",
            "python": f'case "$1" in -m) echo "$*" >> {log};; *) exit 0;; esac',
        },
        ("id", "touch", "mkdir", "env"),
    )
    env = {"PATH": str(bin_), "HOME": str(tmp_path)}
    make = shutil.which("make")
    assert make is not None
    args = [make, "-s", "-C", str(ROOT), f"VENV={venv}", f"PYTHON={bin_ / 'python'}"]
    for pip_ok, want in ((False, [f"-m venv --clear {venv}"]), (True, [])):
        (venv / "bin" / "python").write_text(f"#!/bin/sh\nexit {0 if pip_ok else 1}\n")
        (venv / "bin" / "python").chmod(0o755)
        log.unlink(missing_ok=True)
        (venv / ".debs").unlink(missing_ok=True)
        r = subprocess.run([*args, f"{venv}/.debs"], env=env, capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        got = log.read_text().splitlines() if log.exists() else []
        assert got == want, (pip_ok, got)


def test_make_sh_passes_makes_options_through_unread(tmp_path: Path) -> None:
    """make.sh reads none of make's options: it installs make when missing, then runs it with
    the arguments and MAKEFLAGS as given. Its own reading of dry runs (session 45) refused
    real runs with exit 2 (-Iinclude, MAKEFLAGS=DESTDIR=/opt/inst, a variable named dry in
    the environment) and let --dr, MAKEFLAGS=-n through (re-check review 46); a dry run
    installs make too, since make prints it."""
    log = tmp_path / "calls.log"
    bin_ = _stubs(
        tmp_path,
        {
            "apt-get": (
                f'echo "apt-get $*" >> {log}\n'
                f'[ "$1" = install ] && printf \'#!/bin/sh\\necho "make $* [$MAKEFLAGS]" >> {log}\\n\' '
                f"> {tmp_path}/bin/make && chmod +x {tmp_path}/bin/make\nexit 0"
            ),
            "sudo": 'exec "$@"',
        },
        ("id", "env", "dirname", "printf", "chmod"),
    )
    sh = shutil.which("sh")
    assert sh is not None
    for flags, env in (
        (["-Iinclude"], {}),
        ([], {"MAKEFLAGS": "DESTDIR=/opt/inst"}),
        ([], {"dry": "1"}),
        (["-n"], {}),
        (["--dr"], {}),
        ([], {"MAKEFLAGS": "-n"}),
    ):
        (tmp_path / "bin" / "make").unlink(missing_ok=True)
        log.unlink(missing_ok=True)
        r = subprocess.run(
            [sh, str(ROOT / "make.sh"), *flags, "test"],
            env={"PATH": str(bin_), "HOME": str(tmp_path), **env},
            capture_output=True,
            text=True,
        )
        assert r.returncode == 0, (flags, env, r.stderr)
        calls = log.read_text().splitlines()
        assert calls[:2] == ["apt-get update -qq", "apt-get install -y -qq make"], calls
        want = " ".join(["make", *flags, "test"]) + f" [{env.get('MAKEFLAGS', '')}]"
        assert calls[2:] == [want], (flags, env, calls)
        assert "installing Debian's make" in r.stderr
