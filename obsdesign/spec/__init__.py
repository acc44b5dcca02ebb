"""Spec files: TOML → typed, validated models with exact numbers.

``read_spec(path)`` parses and validates the generic parts (system, sets, simulate scenario)
and keeps ``[method]`` raw; it knows no method. :func:`obsdesign.api.load_spec` binds the
method. Every error is a :class:`SpecError` naming the file, the TOML key and what was
expected.
"""

from obsdesign.spec.loader import read_spec, read_spec_text
from obsdesign.spec.models import Spec, System
from obsdesign.spec.reader import Table, Value

__all__ = ["Spec", "System", "Table", "Value", "read_spec", "read_spec_text"]
