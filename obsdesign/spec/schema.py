"""JSON schema of the spec format (``obsdesign schema``).

The schema documents the shape; the loader's validation (dimensions, bounded sets, positive
definiteness, method options) is stricter than what JSON schema can express.
"""

from __future__ import annotations

from typing import Any

NUM: dict[str, Any] = {"type": "number"}
VEC: dict[str, Any] = {"type": "array", "items": NUM, "minItems": 1}
MAT: dict[str, Any] = {
    "description": "a list of rows; a flat list is one row (one column for B, Bd, Dn, L)",
    "anyOf": [NUM, VEC, {"type": "array", "items": VEC, "minItems": 1}],
}


def _signal() -> dict[str, Any]:
    return {
        "type": "object",
        "required": ["kind"],
        "properties": {
            "kind": {"enum": ["zero", "constant", "windows", "uniform", "outliers", "sequence"]},
            "value": VEC,
            "windows": {
                "type": "array",
                "items": {
                    "type": "object",
                    "required": ["start", "stop", "value"],
                    "properties": {"start": NUM, "stop": NUM, "value": VEC},
                    "description": "value on start <= k <= stop (inclusive)",
                },
            },
            "bound": {"anyOf": [NUM, VEC]},
            "amplitude": {"anyOf": [NUM, VEC]},
            "rate": {**NUM, "minimum": 0, "maximum": 1},
            "values": MAT,
            "seed": {"type": "integer", "minimum": 0},
        },
    }


def spec_schema() -> dict[str, Any]:
    """The JSON schema (draft 2020-12) of a spec file, method sections included."""
    from obsdesign.methods import get_method, method_keys

    sets = {
        "oneOf": [
            {
                "type": "object",
                "required": ["type", "lower", "upper"],
                "properties": {"type": {"const": "box"}, "lower": VEC, "upper": VEC},
            },
            {
                "type": "object",
                "required": ["type", "G", "g"],
                "description": "{x : G x <= g}, bounded and non-empty",
                "properties": {"type": {"const": "polytope"}, "G": MAT, "g": VEC},
            },
            {
                "type": "object",
                "required": ["type", "Q"],
                "description": "{x : |Q x| <= 1}",
                "properties": {"type": {"const": "symmetric-polytope"}, "Q": MAT},
            },
            {
                "type": "object",
                "required": ["type", "E"],
                "description": "{x : (x-c)' E (x-c) <= 1}, E symmetric positive definite",
                "properties": {"type": {"const": "ellipsoid"}, "E": MAT, "center": VEC},
            },
        ]
    }
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "obsdesign spec",
        "type": "object",
        "required": ["system", "method"],
        "properties": {
            "title": {"type": "string"},
            "description": {"type": "string"},
            "reference": {"type": "string"},
            "system": {
                "type": "object",
                "required": ["time", "A", "C"],
                "properties": {
                    "time": {"enum": ["discrete", "continuous"]},
                    "A": MAT,
                    "B": MAT,
                    "C": MAT,
                    "D": MAT,
                    "Bd": {**MAT, "description": "disturbance input (alias B1)"},
                    "B1": MAT,
                    "Dn": {**MAT, "description": "noise input on the output (default identity)"},
                    "sample_time": {**NUM, "exclusiveMinimum": 0},
                    "states": {"type": "array", "items": {"type": "string"}},
                    "parameters": {
                        "type": "object",
                        "additionalProperties": NUM,
                        "description": "named constants for expressions",
                    },
                },
            },
            "sets": {"type": "object", "additionalProperties": sets},
            "method": {"oneOf": [get_method(k).options_schema() for k in method_keys()]},
            "simulate": {
                "type": "object",
                "required": ["horizon", "x0", "xhat0"],
                "properties": {
                    "horizon": {**NUM, "description": "samples (discrete) or seconds (continuous)"},
                    "dt": {**NUM, "exclusiveMinimum": 0},
                    "x0": VEC,
                    "xhat0": VEC,
                    "seed": {"type": "integer", "minimum": 0},
                    "u": _signal(),
                    "disturbance": _signal(),
                    "noise": _signal(),
                },
            },
        },
    }
