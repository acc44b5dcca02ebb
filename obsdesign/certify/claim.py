"""The Claim: one statement a design makes, how it was checked, and the verdict."""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
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
        """The claim as JSON data (``extra`` deep-copied, and left out when empty); the
        fields written out rather than through ``dataclasses.asdict``, whose recursive copy
        of every string was a tenth of a small report's JSON round trip."""
        d: dict[str, Any] = {
            "id": self.id,
            "statement": self.statement,
            "reference": self.reference,
            "check": self.check,
            "margin": self.margin,
            "status": ClaimStatus(self.status).value,
            "detail": self.detail,
            "float_ok": self.float_ok,
        }
        if self.extra:
            d["extra"] = copy.deepcopy(self.extra)
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


def _claim(
    status: ClaimStatus,
    id: str,
    statement: str,
    reference: str,
    check: str,
    margin: Any,
    detail: str,
    float_ok: bool | None,
) -> Claim:
    return Claim(id, statement, reference, check, str(margin), status, detail, float_ok)


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
    status = ClaimStatus.CERTIFIED if passed else ClaimStatus.FAILED
    return _claim(status, id, statement, reference, check, margin, detail, float_ok)


def numerical_claim(
    id: str, statement: str, reference: str, check: str, margin: Any, passed: bool, detail: str
) -> Claim:
    """A claim checked in floating point only: numerical when it passed, failed otherwise."""
    status = ClaimStatus.NUMERICAL if passed else ClaimStatus.FAILED
    return _claim(status, id, statement, reference, check, margin, detail, passed)


def missing_claim(key: str) -> Claim:
    """The failed claim for a parameter a report must carry but does not."""
    return exact_claim(
        f"{key}-present",
        f"the report gives {key}",
        "report",
        "presence",
        0,
        False,
        f"{key} missing",
        False,
    )


class Claims(list[Claim]):
    """The claim toolkit: collects claims built from keyword arguments.

    ``exact(...)`` records a claim decided by an exact check (certified or failed),
    ``numerical(...)`` one checked in floats only (numerical or failed), ``matches(...)`` the
    exact comparison of a reported value with the value the spec fixes (a mismatch is a failed
    claim naming the key), ``checked(...)`` an exact claim decided by a check's result object
    (``.ok``, ``.detail``). Each returns the claim it added.
    """

    def _add(self, c: Claim) -> Claim:
        self.append(c)
        return c

    def exact(
        self,
        *,
        id: str,
        statement: str,
        reference: str,
        check: str,
        passed: bool,
        margin: Any = 0,
        detail: str = "",
        float_ok: bool | None = None,
    ) -> Claim:
        """Add a claim decided by an exact check (certified or failed)."""
        return self._add(
            exact_claim(id, statement, reference, check, margin, passed, detail, float_ok)
        )

    def numerical(self, *, passed: bool, margin: Any = 0, detail: str = "", **text: str) -> Claim:
        """Add a claim checked in floats only (numerical or failed); ``text`` holds ``id``,
        ``statement``, ``reference`` and ``check``."""
        return self._add(
            numerical_claim(
                text["id"],
                text["statement"],
                text["reference"],
                text["check"],
                margin,
                passed,
                detail,
            )
        )

    def checked(
        self, *, id: str, statement: str, reference: str, check: str, result: Any, margin: Any = 0
    ) -> Claim:
        """An exact claim decided by a check's result object: ``passed=result.ok`` and
        ``detail=result.detail`` (e.g. the ``PSDResult`` of ``check_pd`` / ``check_psd``)."""
        return self.exact(
            id=id,
            statement=statement,
            reference=reference,
            check=check,
            passed=bool(result.ok),
            margin=margin,
            detail=result.detail,
        )

    def failed(self, *, id: str, statement: str, reference: str, detail: str) -> Claim:
        """A claim that cannot be checked at all (missing or malformed data): failed."""
        return self.exact(
            id=id,
            statement=statement,
            reference=reference,
            check="presence",
            passed=False,
            detail=detail,
            float_ok=False,
        )

    def matches(self, key: str, reported: Any, expected: Any, where: str) -> bool:
        """Exact comparison of a value the report carries with the one the spec fixes.

        Adds a failed claim ``<key>-matches-spec`` when they differ (nothing when they agree)
        and returns whether they agree. ``where`` names the spec key (``[method].L``)."""
        same = _exact_equal(reported, expected)
        if not same:
            self.exact(
                id=f"{key}-matches-spec",
                statement=f"the reported {key} is the one the spec fixes ({where})",
                reference=f"spec {where}",
                check="exact equality",
                passed=False,
                detail=f"the report's {key} differs from the spec's {where}",
                float_ok=False,
            )
        return same


def _exact_equal(a: Any, b: Any) -> bool:
    import numpy as np

    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        A, B = np.asarray(a, dtype=object), np.asarray(b, dtype=object)
        if A.shape != B.shape:
            return False
        return all(_exact_equal(x, y) for x, y in zip(A.flat, B.flat, strict=True))
    if isinstance(a, (list, tuple)) or isinstance(b, (list, tuple)):
        return _exact_equal(np.asarray(a, dtype=object), np.asarray(b, dtype=object))
    try:
        from obsdesign.certify.exact import Q

        return bool(Q(a) == Q(b))
    except (TypeError, ValueError):
        return bool(a == b)
