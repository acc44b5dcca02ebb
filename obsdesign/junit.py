"""JUnit XML of ``obsdesign check --junit FILE``, so CI systems show failed claims natively.

One ``<testsuite>`` per spec, holding one ``<testcase>`` for the spec itself (``design and
verify``: its exit code; bad input (exit 2) or a solver/internal failure (exit 3) is an
``<error>``, an infeasible design or failed claim (exit 1) or an inconclusive one (exit 4) a
``<failure>``) and one per
verified claim (a failed claim is a ``<failure>`` with the claim's statement and detail; a
numerical claim passes, with a ``<system-out>`` line saying it is not exact). The format is
the common subset of the JUnit XML read by GitHub Actions reporters, GitLab CI
(``artifacts:reports:junit``), Jenkins and Azure: ``testsuites > testsuite > testcase >
failure | error | system-out`` with the attributes ``name``, ``tests``, ``failures``,
``errors``, ``skipped``, ``time``, ``classname``, ``message`` and ``type``
(tests/data/junit.xsd is the schema the test suite validates against).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

#: exit codes (obsdesign.errors) that make the spec's testcase an <error>, not a <failure>
_ERROR_CODES = (2, 3)


#: the characters XML 1.0 forbids (control characters but tab/newline/CR, surrogates,
#: U+FFFE and U+FFFF)
_XML_FORBIDDEN = re.compile("[^\t\n\r\x20-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")


def _clean(text: Any) -> str:
    """Text with the characters XML 1.0 forbids written as escapes (``\\x1b``, ``\\udc80``):
    they were dropped, so a spec file ``f<ESC>[31mred.toml`` was named ``f[31mred.toml``, a
    different file (rendering trial, session 29)."""

    def esc(m: re.Match[str]) -> str:
        o = ord(m[0])
        return f"\\x{o:02x}" if o < 0x100 else f"\\u{o:04x}"

    return _XML_FORBIDDEN.sub(esc, str(text))


def _name(text: Any) -> str:
    """A name (a spec's file, a classname, a claim id) as the text and Markdown tables show it:
    every control character escaped (:func:`obsdesign.errors.escape_controls`: a newline or a
    bidirectional override too), then :func:`_clean`."""
    from obsdesign.errors import escape_controls

    return _clean(escape_controls(str(text)))


def _secs(x: float) -> str:
    return f"{max(float(x), 0.0):.3f}"


def junit_tree(rows: list[Any], name: str = "obsdesign check") -> ET.ElementTree:
    """The JUnit XML tree of ``check`` rows (:class:`obsdesign.api.CheckRow`)."""
    root = ET.Element("testsuites", name=name)
    total = fails = errs = 0
    total_time = 0.0
    for r in rows:
        suite = ET.SubElement(root, "testsuite", name=_name(r.spec))
        cls = _name(f"obsdesign.{r.method}.{r.spec}")
        n = f = e = 0
        case = ET.SubElement(
            suite, "testcase", name="design and verify", classname=cls, time=_secs(r.seconds)
        )
        n += 1
        if r.code != 0:
            kind = "error" if r.code in _ERROR_CODES else "failure"
            el = ET.SubElement(
                case,
                kind,
                message=_clean(f"exit {r.code}: {r.message}"[:500]),
                type=f"exit-{r.code}",
            )
            el.text = _clean(r.message)
            if kind == "error":
                e += 1
            else:
                f += 1
        elif r.summary:
            ET.SubElement(case, "system-out").text = _clean(r.summary)
        for c in r.claims:
            cc = ET.SubElement(suite, "testcase", name=_name(c["id"]), classname=cls, time="0")
            n += 1
            if c["status"] == "failed":
                el = ET.SubElement(
                    cc, "failure", message=_clean(c["statement"][:500]), type="claim-failed"
                )
                el.text = _clean(f"{c['statement']}\n{c['detail']}")
                f += 1
            else:
                ET.SubElement(cc, "system-out").text = _clean(
                    f"{c['status']}: {c['statement']}"
                    + (" (not exact: a numerical claim)" if c["status"] == "numerical" else "")
                )
        suite.set("tests", str(n))
        suite.set("failures", str(f))
        suite.set("errors", str(e))
        suite.set("skipped", "0")
        suite.set("time", _secs(r.seconds))
        total += n
        fails += f
        errs += e
        total_time += r.seconds
    root.set("tests", str(total))
    root.set("failures", str(fails))
    root.set("errors", str(errs))
    root.set("time", _secs(total_time))
    ET.indent(root)
    return ET.ElementTree(root)


def junit_xml(rows: list[Any]) -> str:
    """The JUnit XML document of ``check`` rows, as text."""
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        + ET.tostring(junit_tree(rows).getroot(), encoding="unicode")
        + "\n"
    )


def write_junit(path: str | Path, rows: list[Any], force: bool = False) -> Path:
    """Write the JUnit XML of ``rows`` to ``path`` atomically (the output checks of
    :func:`obsdesign.report.model.write_atomic` apply)."""
    from obsdesign.report.model import write_atomic

    return write_atomic(path, junit_xml(rows), force)
