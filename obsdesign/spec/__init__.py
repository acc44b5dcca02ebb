"""Spec files: TOML → typed, validated models with exact numbers.

``load_spec(path)`` is the entry point; every error it raises is a :class:`SpecError` naming
the file, the TOML key and what was expected.
"""

from obsdesign.spec.loader import load_spec, load_spec_text
from obsdesign.spec.models import Spec, System
from obsdesign.spec.reader import Table, Value

__all__ = ["Spec", "System", "Table", "Value", "load_spec", "load_spec_text"]
