"""JSON schema of the spec format (``obsdesign schema``).

The schema documents the shape; the loader's validation (dimensions, bounded sets, positive
definiteness, method options) is stricter than what JSON schema can express.
"""

from __future__ import annotations

from typing import Any

NUM: dict[str, Any] = {"type": "number"}
VEC: dict[str, Any] = {"type": "array", "items": NUM, "minItems": 1}
#: a vector key the reader also takes as one number (a box bound, x0, a signal's value, an
#: ellipsoid's center, the amplitudes: a scalar is a vector of length 1 — of the set's or
#: plant's dimension, a rule across keys that the schema does not state); VEC refused
#: lower = -3 of a 1-D box the tool takes (re-check and docs reviews 46)
BOUND: dict[str, Any] = {"anyOf": [NUM, VEC]}
MAT: dict[str, Any] = {
    "description": "a list of rows; a flat list is one row (one column for B, Bd, Dn, L)",
    "anyOf": [NUM, VEC, {"type": "array", "items": VEC, "minItems": 1}],
}


DIM: dict[str, Any] = {
    "type": "integer",
    "minimum": 1,
    "description": "dimension of the set (default: the number of states)",
}


def _signal() -> dict[str, Any]:
    return {
        "type": "object",
        "required": ["kind"],
        "properties": {
            "kind": {"enum": ["zero", "constant", "windows", "uniform", "outliers", "sequence"]},
            "value": BOUND,
            "windows": {
                "type": "array",
                "minItems": 1,  # windows = [] is refused by the reader (re-check review 46)
                "items": {
                    "type": "object",
                    "required": ["start", "stop", "value"],
                    "properties": {"start": NUM, "stop": NUM, "value": BOUND},
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


EXPR: dict[str, Any] = {"type": "string", "format": "obsdesign-expression"}
EXPRS: dict[str, Any] = {
    "anyOf": [EXPR, {"type": "array", "items": EXPR, "minItems": 1}],
    "description": "expressions in the safe expression language, one per component",
}


def _nonlinearity() -> dict[str, Any]:
    """``[nonlinearity]``: bound data of the plant's nonlinearity ψ (the expressions live in
    ``[system] psi``). Read by the ``impulsive`` method (Assumption 1 of the impulsive-observer
    paper): ``lipschitz_x``, or the blocks ``[nonlinearity.o]`` / ``[nonlinearity.n]`` in
    z = T x (each: ``sector = [a, b]``, ``lipschitz``, or a QSR triple ``Q``, ``S``, ``R``; and
    ``cross``), and the optional falsification box ``[nonlinearity.falsify]``."""
    block = {
        "type": "object",
        "additionalProperties": False,
        "description": "one of sector, lipschitz or (Q, S, R); cross: the coupling constant",
        "properties": {
            "sector": {**VEC, "minItems": 2, "maxItems": 2, "description": "[a, b]"},
            "lipschitz": {**NUM, "minimum": 0},
            "Q": MAT,
            "S": MAT,
            "R": MAT,
            "cross": {**NUM, "minimum": 0},
        },
    }
    return {
        "type": "object",
        "additionalProperties": False,
        "description": "bound data of the plant's nonlinearity ψ ([system] psi): a Lipschitz "
        "constant, or sector / QSR data per block; read by the methods that declare it "
        "(impulsive)",
        "properties": {
            "lipschitz_x": {**NUM, "minimum": 0, "description": "|ψ(x) − ψ(x')| ≤ ℓ|x − x'|"},
            "o": {**block, "description": "the output block of z = T x (Assumption 1)"},
            "n": {**block, "description": "the other block of z = T x (Assumption 1)"},
            "falsify": {
                "type": "object",
                "required": ["lower", "upper"],
                "additionalProperties": False,
                "description": "sample pairs in the box [lower, upper] to look for a "
                "violation of the bound (a numerical check, not a certificate)",
                "properties": {
                    "lower": BOUND,
                    "upper": BOUND,
                    # impulsive.options.MAX_SAMPLES (this layer imports no method; a test
                    # ties the two): 2,000,000 validated, the tool refused it (docs review 45)
                    "samples": {"type": "integer", "minimum": 10, "maximum": 1_000_000},
                    "seed": {"type": "integer", "minimum": 0},
                    "on_violation": {"enum": ["fail", "warn"]},
                },
            },
        },
    }


def expression_keys(schema: dict[str, Any]) -> list[str]:
    """The dotted keys of ``schema`` whose values are expressions (``"format":
    "obsdesign-expression"``), e.g. ``system.f`` or ``method.F``."""
    out: set[str] = set()

    def walk(node: Any, path: list[str]) -> None:
        if isinstance(node, dict):
            if node.get("format") == "obsdesign-expression":
                out.add(".".join(path))
            for k, v in node.items():
                if k == "properties" and isinstance(v, dict):
                    for name, sub in v.items():
                        walk(sub, [*path, name])
                elif k in ("anyOf", "oneOf", "allOf") and isinstance(v, list):
                    for sub in v:
                        walk(sub, path)
                elif k in ("items", "additionalProperties") and isinstance(v, dict):
                    walk(v, path)

    walk(schema, [])
    return sorted(out)


def spec_schema(
    method_schemas: list[dict[str, Any]],
    simulate_keys: dict[str, Any] | None = None,
    simulate_own: dict[str, dict[str, Any]] | None = None,
) -> dict[str, Any]:
    """The JSON schema (draft 2020-12) of a spec file.

    ``method_schemas`` are the methods' ``[method]`` schemas and ``simulate_keys`` the union of
    their own ``[simulate]`` keys; ``simulate_own`` maps each method key to its own
    ``[simulate]`` keys and their schemas, so that a spec of one method with another's key is
    refused by the schema as by the tool (a lyapunov spec with theta_m validated, then design
    said exit 2; outsider trial, session 29), and a key two methods share is checked by the
    rule of the spec's method (the last method's rule applied to every method's spec:
    search-space ``substeps = 0`` was refused, impulsive ``runs = 200000`` accepted; docs
    review 45). The caller (the API) collects them, so this layer imports no method."""

    sets = {
        "oneOf": [
            {
                "type": "object",
                "required": ["type", "lower", "upper"],
                "properties": {
                    "type": {"const": "box"},
                    "lower": BOUND,
                    "upper": BOUND,
                    "dim": DIM,
                },
                "additionalProperties": False,
            },
            {
                "type": "object",
                "required": ["type", "G", "g"],
                "description": "{x : G x <= g}, bounded and non-empty",
                "properties": {"type": {"const": "polytope"}, "G": MAT, "g": VEC, "dim": DIM},
                "additionalProperties": False,
            },
            {
                "type": "object",
                "required": ["type", "Q"],
                "description": "{x : |Q x| <= 1}",
                "properties": {"type": {"const": "symmetric-polytope"}, "Q": MAT, "dim": DIM},
                "additionalProperties": False,
            },
            {
                "type": "object",
                "required": ["type", "E"],
                "description": "{x : (x-c)' E (x-c) <= 1}, E symmetric positive definite",
                "properties": {
                    "type": {"const": "ellipsoid"},
                    "E": MAT,
                    "center": BOUND,
                    "dim": DIM,
                },
                "additionalProperties": False,
            },
        ]
    }
    common = ["horizon", "dt", "x0", "xhat0", "seed", "u", "disturbance", "noise"]
    per_method = [
        {
            "if": {
                "required": ["method"],
                "properties": {
                    "method": {"required": ["key"], "properties": {"key": {"const": k}}}
                },
            },
            "then": {
                "properties": {
                    "simulate": {
                        "propertyNames": {"enum": [*common, *sorted(own)]},
                        "properties": dict(sorted(own.items())),
                    }
                }
            },
        }
        for k, own in (simulate_own or {}).items()
    ]
    schema = {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "obsdesign spec",
        **({"allOf": per_method} if per_method else {}),
        "type": "object",
        "required": ["system", "method"],
        # unknown keys are errors in the tool, so in the schema too: the top level, [system],
        # [simulate] and the sets were open (a typo validated; outsider trial, session 22)
        "additionalProperties": False,
        "properties": {
            "title": {"type": "string"},
            "description": {"type": "string"},
            "reference": {"type": "string"},
            "system": {
                "type": "object",
                "required": ["time"],
                "additionalProperties": False,
                "description": "the plant: linear data (A, C, ...), expressions (f or psi, h), or both",
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
                    "inputs": {
                        "type": "integer",
                        "minimum": 0,
                        "description": "number of inputs when B is absent",
                    },
                    "disturbances": {
                        "type": "integer",
                        "minimum": 0,
                        "description": "number of disturbance inputs when Bd is absent",
                    },
                    "f": {
                        **EXPRS,
                        "description": "x⁺ or ẋ as expressions of states, u1.., d1.., t",
                    },
                    "psi": {
                        **EXPRS,
                        "description": "additive term: x⁺ or ẋ = A x + B u + Bd d + ψ",
                    },
                    "h": {**EXPRS, "description": "y as expressions of states, u1.., v1.., t"},
                    "u": {**EXPRS, "description": "open-loop input u(t) as expressions of t"},
                    "parameters": {
                        "type": "object",
                        "additionalProperties": NUM,
                        "description": "named constants for expressions",
                    },
                },
            },
            "sets": {"type": "object", "additionalProperties": sets},
            "nonlinearity": _nonlinearity(),
            "method": {"oneOf": method_schemas},
            "simulate": {
                "type": "object",
                "required": ["horizon", "x0", "xhat0"],
                "additionalProperties": False,
                "properties": {
                    "horizon": {
                        **NUM,
                        "exclusiveMinimum": 0,
                        "description": "samples (discrete: an integer ≥ 1) or seconds (continuous)",
                    },
                    "dt": {**NUM, "exclusiveMinimum": 0},
                    "x0": BOUND,
                    "xhat0": BOUND,
                    "seed": {"type": "integer", "minimum": 0},
                    "u": _signal(),
                    "disturbance": _signal(),
                    "noise": _signal(),
                    **(simulate_keys or {}),
                },
            },
        },
    }
    return _capped_integers(schema)


#: the largest integer a spec key takes (obsdesign.limits.INT_MAX; a seed takes any size)
_INT_MAX = 2**63 - 1


def _capped_integers(node: Any, key: str = "") -> Any:
    """``node`` with ``"maximum": 2^63 − 1`` on every integer schema that has no maximum,
    but a seed's: the tool refuses larger integers by name (session 44), and the schema
    accepted them (re-check review 45)."""
    if isinstance(node, list):
        return [_capped_integers(x, key) for x in node]
    if not isinstance(node, dict):
        return node
    out = {}
    for k, v in node.items():
        if k == "properties" and isinstance(v, dict):
            out[k] = {name: _capped_integers(x, name) for name, x in v.items()}
        else:
            out[k] = _capped_integers(v, key)
    if out.get("type") == "integer" and "maximum" not in out and key != "seed":
        out["maximum"] = _INT_MAX
    return out
