"""The Claim: one statement a design makes, how it was checked, and the verdict."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from enum import StrEnum
from typing import Any


class ClaimStatus(StrEnum):
    """``certified``: an exact check passed. ``numerical``: checked in floats only (with the
    margin), by design of the claim. ``failed``: the check did not pass."""

    CERTIFIED = "certified"
    NUMERICAL = "numerical"
    FAILED = "failed"


@dataclass
class Claim:
    """One checkable statement of a design.

    ``float_ok`` records whether the same inequality holds in float64: a claim that fails
    exactly but holds in floats makes the run *inconclusive* (exit 4), not infeasible.
    """

    id: str
    statement: str
    reference: str
    check: str
    margin: str
    status: ClaimStatus
    detail: str = ""
    float_ok: bool | None = None
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.status != ClaimStatus.FAILED

    def to_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["status"] = self.status.value
        if not self.extra:
            d.pop("extra")
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Claim:
        return cls(
            id=str(d["id"]),
            statement=str(d["statement"]),
            reference=str(d["reference"]),
            check=str(d["check"]),
            margin=str(d["margin"]),
            status=ClaimStatus(d["status"]),
            detail=str(d.get("detail", "")),
            float_ok=d.get("float_ok"),
            extra=dict(d.get("extra", {})),
        )


def exact_claim(
    id: str,
    statement: str,
    reference: str,
    check: str,
    margin: Any,
    passed: bool,
    detail: str,
    float_ok: bool | None = None,
) -> Claim:
    """A claim decided by an exact check: certified when it passed, failed otherwise."""
    return Claim(
        id=id,
        statement=statement,
        reference=reference,
        check=check,
        margin=str(margin),
        status=ClaimStatus.CERTIFIED if passed else ClaimStatus.FAILED,
        detail=detail,
        float_ok=float_ok,
    )


def numerical_claim(
    id: str, statement: str, reference: str, check: str, margin: Any, passed: bool, detail: str
) -> Claim:
    """A claim checked in floating point only: numerical when it passed, failed otherwise."""
    return Claim(
        id=id,
        statement=statement,
        reference=reference,
        check=check,
        margin=str(margin),
        status=ClaimStatus.NUMERICAL if passed else ClaimStatus.FAILED,
        detail=detail,
        float_ok=passed,
    )
