"""Benchmarks of the set-invariant method (issue 4, paper 003), printed with their targets.

1. Example 7.1: design + exact verify (target < 0.5 s).
2. Example 7.2: symmetric C_K^∞, then the general algorithm to a certified invariant
   polyhedron, design + verify (target < 5 s).
3. The paper's own test: 20 random 3rd- and 4th-order single-output systems (seeds 0-19),
   Ω = {|e|∞ <= 1}, D = {|d| <= 1} through B1 with entries ~ N(0, 0.05²), η̄ = 0.01.
   λ rule: A is drawn with spectral radius ρ(A) in [0.5, 0.95] and λ = (1 + ρ(A))/2, halfway
   between the contraction the open loop gives (v = 0) and 1. General algorithm with
   mirrored images, Δδ = 1e-3, at most 60 iterations, the default time_limit (30 s).
   Targets (issue 12 item 2): every system certified or refused with a reason in < 60 s;
   median (design + exact certify in one process) <= 1.5× the float-only design.
4. Polytope primitives vs the obvious alternatives: vertex enumeration and hull vs scipy's
   qhull (target within 2×), redundancy removal vs one HiGHS LP per row (no slower), exact
   certificate check (n <= 4, a few hundred facets) under 1 s.
5. Zero disagreement between the float design and the exact certificate.
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path

import numpy as np

from obsdesign.methods.setinvariant.spectext import spec_text

ROOT = Path(__file__).resolve().parents[1]


def _spec_text(A: np.ndarray, B1: np.ndarray, C: np.ndarray, lam: float) -> str:
    """The benchmark's spec: the general algorithm with mirrored images, Δδ = 1e-3, ≤ 60 iterations."""
    return spec_text(
        A, B1, C, lam, algorithm="general", mirror=True, delta_tol=0.001, max_iterations=60
    )


def random_system(seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The benchmark's system of ``seed`` (3 states for even seeds, 4 for odd) and its λ."""
    rng = np.random.default_rng(seed)
    n = 3 + seed % 2
    A = rng.normal(size=(n, n))
    rho = rng.uniform(0.5, 0.95)
    A = np.round(A * rho / max(abs(np.linalg.eigvals(A))), 4)
    C = np.round(rng.normal(size=(1, n)), 4)
    B1 = np.round(rng.normal(size=(n, 1)) * 0.05, 4)
    rho = float(max(abs(np.linalg.eigvals(A))))
    return A, B1, C, round((1 + rho) / 2, 4)


def _timed(f, *a, **k):
    t = time.perf_counter()
    r = f(*a, **k)
    return r, time.perf_counter() - t


def _best(f, *a, repeat: int = 7):
    """Best of ``repeat`` runs (the machine is shared: the minimum is the stable figure)."""
    return min(_timed(f, *a)[1] for _ in range(repeat))


def examples() -> None:
    import tempfile

    from obsdesign import api

    with tempfile.TemporaryDirectory() as d:  # warm-up: imports (scipy, cdd, flint)
        api.design(ROOT / "specs" / "dorea-pimenta-7-1.toml", Path(d) / "w.json")

    for name, target in (("dorea-pimenta-7-1", 0.5), ("dorea-pimenta-7-2", 5.0)):
        with tempfile.TemporaryDirectory() as d:
            out = Path(d) / "r.json"
            rep, td = _timed(api.design, ROOT / "specs" / f"{name}.toml", out)
            ver, tv = _timed(api.verify, out)
        assert rep.exit_code() == 0 and ver.exit_code() == 0, name
        p = rep.parameters
        print(
            f"{name}: design {td:.3f} s + exact verify {tv:.3f} s = {td + tv:.3f} s (target < {target} s); "
            f"{p['iterations']} iterations, {p['facets']} facets, certified factor {float(p['contractivity']):.9g}"
        )


def _float_design(sp) -> float:
    """Seconds of the same design with the exact stages switched off (float64 only: the
    iterations plus the float final stage), the baseline of issue 12 item 2."""
    from obsdesign.errors import ObsdesignError
    from obsdesign.methods import get_method
    from obsdesign.sets import polytope_ops as po

    saved = po.HAVE_GMP
    po.HAVE_GMP = False
    t0 = time.perf_counter()
    try:
        get_method("set-invariant").design(sp)
    except ObsdesignError:  # refused (time budget): the refusal's time is the baseline
        pass
    finally:
        po.HAVE_GMP = saved
    return time.perf_counter() - t0


def paper_test(count: int = 20) -> None:
    """Issue 12 item 2: each system certified or refused with a reason in < 60 s (design +
    exact certify in one process, the design's exact hull and Theorem 3.1 reused, then an
    independent verify of the JSON report that recomputes everything); the median of
    (design + certify) / float-only design <= 1.5, each ratio paired in one run (medians of
    5 interleaved pairs for designs under 2 s, of 3 for 2-15 s)."""
    import tempfile

    from obsdesign import api
    from obsdesign.api import load_spec_text
    from obsdesign.errors import ObsdesignError
    from obsdesign.methods.setinvariant import memo

    rows = []
    disagree = refused = 0
    worst = 0.0
    for seed in range(count):
        A, B1, C, lam = random_system(seed)
        sp = load_spec_text(_spec_text(A, B1, C, lam), f"random-{seed}.toml")
        tf = _float_design(sp)
        h0 = memo.STATS["hits"]
        t0 = time.perf_counter()
        try:
            rep = api.design(sp)
        except ObsdesignError as e:
            t = time.perf_counter() - t0
            refused += 1
            worst = max(worst, t)
            print(
                f"  seed {seed:2d} n={A.shape[0]} λ={lam:.4f}: refused after {t:.1f} s: {e.message}"
            )
            continue
        td = time.perf_counter() - t0
        # the machine is shared: the median of 5 interleaved pairs (3 for designs of 2-15 s)
        extra = 4 if td < 2.0 else 2 if td < 15.0 else 0
        pairs = [(tf, td)] + [(_float_design(sp), _timed(api.design, sp)[1]) for _ in range(extra)]
        tf = statistics.median(p[0] for p in pairs)
        td = statistics.median(p[1] for p in pairs)
        with tempfile.TemporaryDirectory() as d:
            out = Path(d) / "r.json"
            out.write_text(rep.to_json())
            ver, tv = _timed(api.verify, out)
        p = rep.parameters
        ok = rep.exit_code() == 0
        if p["converged"] and not ok:
            disagree += 1
        if ver.exit_code() != rep.exit_code():
            disagree += 1
        worst = max(worst, td, tv)
        rows.append((seed, td, tf, tv, ok))
        print(
            f"  seed {seed:2d} n={A.shape[0]} λ={lam:.4f}: {p['iterations']:3d} iterations, "
            f"{p['facets']:4d} facets, {'certified' if ok else 'NOT certified'}; float-only design "
            f"{tf:6.2f} s, design + certify {td:6.2f} s (ratio {td / tf:4.2f}, "
            f"{memo.STATS['hits'] - h0} exact checks reused), independent verify {tv:6.2f} s"
        )
    cert = sum(r[4] for r in rows)
    med = statistics.median(r[1] / r[2] for r in rows) if rows else float("nan")
    medt = statistics.median(r[1] for r in rows) if rows else float("nan")
    print(f"random systems: {cert}/{count} certified, {refused} refused with a reason")
    print(
        f"slowest system (design + certify, or verify, or refusal): {worst:.1f} s (target < 60 s)"
    )
    print(f"median (design + certify) / float-only design: {med:.2f} (target <= 1.5)")
    print(f"median design + certify: {medt:.3f} s")
    print(f"float design vs exact certificate disagreements: {disagree} (target 0)")


def primitives() -> None:
    from scipy.optimize import linprog
    from scipy.spatial import ConvexHull

    from obsdesign.methods.setinvariant import certificate as ce
    from obsdesign.methods.setinvariant import lps
    from obsdesign.sets import polytope_ops as po

    rng = np.random.default_rng(0)
    P = rng.normal(size=(2000, 3))
    t_ours = _best(po.v_to_h, P)
    t_qh = _best(ConvexHull, P)
    print(
        f"hull of 2000 points in 3-D: ours {t_ours * 1e3:.1f} ms, scipy qhull {t_qh * 1e3:.1f} ms, ratio {t_ours / t_qh:.2f} (target <= 2)"
    )
    G = po.hull(P).G
    t_v = _best(po.h_to_v, G)
    print(
        f"vertex enumeration, {len(G)} facets: ours {t_v * 1e3:.1f} ms, qhull (hull of the points) {t_qh * 1e3:.1f} ms, ratio {t_v / t_qh:.2f} (target <= 2)"
    )
    Gr = np.vstack([G, 0.5 * G[:100]])  # 100 redundant rows

    def lp_per_row() -> int:
        keep = 0
        for i in range(len(Gr)):
            others = np.delete(Gr, i, axis=0)
            r = linprog(
                -Gr[i], A_ub=others, b_ub=np.ones(len(others)), bounds=(None, None), method="highs"
            )
            keep += r.status == 0 and -r.fun > 1 + 1e-9
        return keep

    R = po.remove_redundant(Gr)
    t_red = _best(po.remove_redundant, Gr)
    k, t_lp = _timed(lp_per_row)
    print(
        f"redundancy removal, {len(Gr)} rows: ours {t_red * 1e3:.1f} ms ({len(R)} kept), one HiGHS LP per row {t_lp * 1e3:.0f} ms ({k} kept), ratio {t_red / t_lp:.3f} (target <= 1)"
    )
    # exact certificate check on a few-hundred-facet polytope (n = 3)
    A = np.array([[0.6, 0.5, 0.0], [-0.5, 0.6, 0.2], [0.0, -0.3, 0.5]])
    Cc = np.array([[1.0, 0.3, -0.4]])
    S = rng.normal(size=(150, 3))
    S = S / np.linalg.norm(S, axis=1)[:, None]
    Gq, vrep = po.exact_hull(po.qarray(S))
    ex = ce.ExactProblem(
        po.qarray(A),
        np.zeros((3, 0), dtype=object),
        po.qarray(Cc),
        Gq,
        vrep.V,
        np.zeros((0, 0), dtype=object),
        po.snap(0.0),
        po.snap(10.0),
    )
    res = ce.theorem31(ex, Gq, v_solver=lps.eps_batch, vrep=vrep)

    def check() -> bool:
        ok, _, vr = po.exact_check_forms(Gq, vrep.V)
        return ok and ce.theorem31(ex, Gq, vs=res.vs, zs_given=res.zs, vrep=vr).ok

    ok, t_chk = _timed(check)
    assert ok
    print(
        f"exact certificate check (V/H forms agree + Theorem 3.1), n = 3, {len(Gq)} facets, "
        f"{len(vrep.V)} vertices: {t_chk:.3f} s (target < 1 s)"
    )


def main() -> None:
    import os

    examples()
    primitives()
    # `make bench-quick` sets OBSDESIGN_BENCH_QUICK: 5 random systems instead of 20 (~10 min)
    paper_test(5 if os.environ.get("OBSDESIGN_BENCH_QUICK") else 20)


if __name__ == "__main__":
    main()
