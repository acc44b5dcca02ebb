"""Reports: the JSON model (schema_version, tool, method, spec, spec_sha256, parameters,
claims, solver, timings) and its renderers (terminal, Markdown)."""

from obsdesign.report.model import SCHEMA_VERSION, Report, write_atomic

__all__ = ["SCHEMA_VERSION", "Report", "write_atomic"]
