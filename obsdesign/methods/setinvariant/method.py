"""Set-invariant estimators (method key ``set-invariant``), Dórea & Pimenta (paper 003).

Design: a D-(C,A)-λ-contractive polyhedron {e : G e <= 1} containing Ω, by the symmetric
algorithm (Section VI) or the general algorithm (Section V), the piecewise-affine injection
table of Proposition 4.1 (single output) and, when it exists, a linear gain L (Proposition
7.1); all proved exactly (Theorem 3.1 at every z of Z_d, in rationals).

Choices where the paper is ambiguous (documented in docs/readme-set-invariant.md):

* iterations count the checks of the stopping condition (Example 7.1: "2 iterations" = the
  check on Ω, which gives 2.4, and the check on the first hull, which passes);
* the stopping rule ε^i <= λ(1 + Δδ) only gives λ(1 + Δδ)-contractivity; with
  ``strict = true`` (default) the design continues with the hull scaled by
  λ/(1 + Δδ) until the *certified* factor is <= λ;
* the general algorithm slices at the worst z^l of Z_d (so |C e − z^l| <= η̄), which is
  what Theorem 3.1 checks; the printed step 7 writes |Ce − Ce^i| <= η̄;
* when the symmetric C_K^∞ meets condition (14) but not Theorem 3.1 (Example 7.2),
  ``fallback = "general"`` continues with the general algorithm from C_K^∞.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np
from flint import fmpq

from obsdesign.certify.claim import Claim, exact_claim
from obsdesign.errors import InfeasibleError
from obsdesign.methods.base import Design, Method, Progress
from obsdesign.params import Parameters, exact_param
from obsdesign.sets import Box, Polytope
from obsdesign.sets import polytope_ops as po
from obsdesign.spec.models import Spec
from obsdesign.spec.reader import Table

from . import algorithms as al
from . import certificate as ce
from . import laws, lps, numerical
from .linear import admissible_gains
from .problem import build, check_detectable, necessary_condition

REF = "Dórea & Pimenta, Design of set-invariant estimators (paper 003)"
ALGORITHMS = ("symmetric", "general", "none")
LAWS = ("interpolated", "time-varying", "online-lp", "linear")


@dataclass
class Options:
    """``[method]`` of ``set-invariant``."""

    omega: str
    disturbance: str | None
    D: Any  # Box | Polytope | None: the disturbance set (dimension = columns of B1)
    eta_bar: fmpq
    lam: fmpq
    algorithm: str
    delta_tol: fmpq
    max_iterations: int
    mirror: bool
    strict: bool
    fallback: str
    L: np.ndarray | None
    linear_law: bool


class SetInvariant(Method):
    key = "set-invariant"
    title = "Set-invariant estimator (D-(C,A)-λ-contractive polyhedron)"
    paper = "003 (Dórea & Pimenta)"

    # -- spec -------------------------------------------------------------------------------
    def parse_options(self, table: Table, spec: Spec) -> Options:
        s = spec.system
        if not s.discrete:
            raise SpecErrorAt(
                spec, "system.time", "expected time = 'discrete' (the method is discrete-time)"
            )
        omega = table.str("omega")
        if omega not in spec.sets:
            raise table.error("omega", f"expected the name of a set in [sets]; got {omega!r}")
        om = spec.sets[omega]
        if not isinstance(om, (Box, Polytope)):
            raise table.error(
                "omega", "expected a box or (symmetric-)polytope set (Ω must be a polyhedron)"
            )
        from .problem import omega_rows

        try:
            omega_rows(om)
        except ValueError as e:
            raise table.error("omega", f"Ω: {e}") from None
        dist, Dset = _parse_disturbance(table, spec)
        eta = table.scalar("eta_bar", default=fmpq(0), min=0).q
        if s.p > 0:
            Dn = np.asarray(s.Dn.q, dtype=object)
            if Dn.shape != (s.p, s.p) or any(
                Dn[i, j] != (1 if i == j else 0) for i in range(s.p) for j in range(s.p)
            ):
                raise SpecErrorAt(
                    spec,
                    "system.Dn",
                    "expected the identity (the noise is η in z = C e + η, |η| <= eta_bar)",
                )
        lam = table.scalar("lambda", min=0, max=1, strict_min=True).q
        algorithm = table.str("algorithm", default="symmetric", choices=ALGORITHMS)
        dtol = table.scalar("delta_tol", default=fmpq(1, 10**6), min=0, strict_min=True).q
        maxit = table.int("max_iterations", default=100, min=1)
        mirror = table.bool("mirror", default=False)
        strict = table.bool("strict", default=True)
        fallback = table.str("fallback", default="general", choices=("general", "none"))
        L = None
        if table.has("L"):
            L = table.matrix("L", rows=s.n, cols=s.p, vector_as="column").q
        linear_law = table.bool("linear_law", default=True)
        if s.p != 1:
            if s.p != s.n - 1:
                raise SpecErrorAt(
                    spec,
                    "system.C",
                    f"has {s.p} outputs with n = {s.n} states: Theorem 3.1 and Proposition 4.1 cover "
                    "single-output systems and Proposition 7.1 covers p = n − 1 outputs (linear law); "
                    "this system is neither",
                )
            if eta != 0:
                raise table.error(
                    "eta_bar",
                    f"expected 0: with p = {s.p} = n − 1 outputs only Proposition 7.1 applies, and it assumes no noise",
                )
            if algorithm != "symmetric":
                raise table.error(
                    "algorithm",
                    f"expected 'symmetric': with p = {s.p} > 1 outputs only the symmetric algorithm and the linear law (Proposition 7.1) apply",
                )
        table.done()
        return Options(
            omega,
            dist,
            Dset,
            eta,
            lam,
            algorithm,
            dtol,
            maxit,
            mirror,
            strict,
            fallback,
            L,
            linear_law,
        )

    # -- design -----------------------------------------------------------------------------
    def design(self, spec: Spec, progress: Progress | None = None) -> Design:
        o: Options = spec.options
        s = spec.system
        t0 = time.perf_counter()
        data = build(spec)
        fl, ex = data.fl, data.ex
        exact_mode = ex is not None  # False without cdd.gmp: float-only, numerical claims
        lam = float(o.lam)
        dd = float(o.delta_tol)
        check_detectable(fl.A, fl.C, lam)
        notes: list[str] = []
        params = Parameters()
        history: list[dict[str, float]] = []
        single = s.p == 1

        Vo_f = po.qfloat(ex.Vo) if ex is not None else numerical.omega_vertices(fl)
        vreps: dict[int, Any] = {}

        def exact_stage(P: np.ndarray) -> tuple[np.ndarray, Any]:
            """Exact polytope from the float vertices P: Ω's vertices exactly, the others
            snapped (po.snap); one exact hull gives G and the edges (po.exact_hull).
            Without cdd.gmp: the float hull and Theorem 3.1 in float64 (numerical.py)."""
            if ex is None:
                Gf, resf, vrf = numerical.float_stage(fl, P, lam)
                vreps[id(Gf)] = vrf
                return Gf, resf
            near = (
                np.array([np.abs(Vo_f - p).max(axis=1).min() <= 1e-9 for p in P])
                if len(P)
                else np.zeros(0, bool)
            )
            Pq = np.vstack([ex.Vo, po.rationalize(P[~near])]) if (~near).any() else ex.Vo
            Gq, vrep = po.exact_hull(Pq)
            vreps[id(Gq)] = vrep
            if not single:
                return Gq, None
            return Gq, ce.theorem31(ex, Gq, v_solver=lps.eps_batch, vrep=vrep)

        converged = True
        sym_eps_max = None
        if o.algorithm == "none":
            it = 1
            Gq, res = exact_stage(Vo_f)
        elif o.algorithm == "symmetric":
            r = al.symmetric(fl, lam, lam * (1 + dd), o.max_iterations, progress, history=history)
            it, converged = r.iterations, r.converged
            Gq, res = exact_stage(r.P)
            if converged and single and res is not None and not res.ok:
                zs, epsz = lps.epsilon_profile(r.G, fl.A, fl.B1, fl.C[0], fl.Dv, fl.eta)
                sym_eps_max = float(np.max(epsz))
                params["symmetric_G"] = Gq
                params["symmetric_iterations"] = it
                params["symmetric_contractivity"] = sym_eps_max
                msg = (
                    f"the symmetric C_K^∞ meets condition (14) after {it} iterations but not "
                    f"Theorem 3.1: max ε(z) = {sym_eps_max:.6g} > λ = {lam:g}"
                )
                notes.append(msg)
                if progress:
                    progress(msg)
                if o.fallback == "general":
                    r = al.general(
                        fl,
                        lam / (1 + dd),
                        lam,
                        o.max_iterations,
                        o.mirror,
                        start=r.P,
                        progress=progress,
                        it0=it,
                        history=history,
                    )
                    it, converged = r.iterations, r.converged
                    Gq, res = exact_stage(r.P)
                    notes.append(
                        f"general algorithm (Section V) continued from C_K^∞: {it} iterations in all"
                    )
        else:
            lam_run = lam / (1 + dd) if o.strict else lam
            lam_stop = lam if o.strict else lam * (1 + dd)
            r = al.general(
                fl,
                lam_run,
                lam_stop,
                o.max_iterations,
                o.mirror,
                progress=progress,
                history=history,
            )
            it, converged = r.iterations, r.converged
            Gq, res = exact_stage(r.P)
        # strict: the certified factor must be <= λ; continue with the scaled hull if needed
        if (
            single
            and o.strict
            and converged
            and res is not None
            and not res.ok
            and o.algorithm != "none"
        ):
            if float(res.factor) <= lam * (1 + 2 * dd) and (
                sym_eps_max is None or o.fallback == "general"
            ):
                notes.append(
                    f"certified factor {float(res.factor):.9g} > λ: iterating with the hull scaled by "
                    "λ/(1 + Δδ) until the certified factor is <= λ"
                )
                r = al.general(
                    fl,
                    lam / (1 + dd),
                    lam * (1 - 1e-12),
                    o.max_iterations,
                    o.mirror,
                    start=po.qfloat(vreps[id(Gq)].V),
                    progress=progress,
                    it0=it,
                    history=history,
                )
                it, converged = r.iterations, r.converged
                Gq, res = exact_stage(r.P)
        params["G"] = Gq
        params["V"] = vreps[id(Gq)].V
        params["lambda"] = o.lam
        params["iterations"] = it
        params["converged"] = bool(converged)
        params["facets"] = len(Gq)
        if not converged:
            notes.append(
                f"NOT CONVERGED after {it} iterations (max_iterations = {o.max_iterations}); the last polyhedron is reported"
            )
        if res is not None:
            params["contractivity"] = res.factor
            dt = object if exact_mode else float
            params["breakpoints"] = np.array(res.zs, dtype=dt)
            params["v_breakpoints"] = np.array(res.vs, dtype=dt).reshape(len(res.zs), s.n)
            if len(res.zs) > 1:
                Ls, ws = laws.pieces(list(res.zs), [list(v) for v in res.vs])
                params["L_pieces"] = np.array(Ls, dtype=dt)
                params["w_pieces"] = np.array(ws, dtype=dt)
            params["vertices"] = res.n_vertices
            if res.exact_lp:
                notes.append(
                    f"{res.exact_lp} breakpoint injections came from the exact (cdd.gmp) LP (9)"
                )
        # linear law (Proposition 7.1 / any admissible L)
        V = vreps[id(Gq)].V
        if o.linear_law and s.p == s.n - 1:
            gs = (
                admissible_gains(ex, Gq, V)
                if ex is not None
                else numerical.float_gains(fl, lam, Gq, V)
            )
            if gs.L is not None:
                params["L"] = gs.L
                params["L_factor"] = gs.factor
                if gs.vertices:
                    params["L_admissible_vertices"] = np.array(
                        [v.reshape(-1) for v in gs.vertices], dtype=object
                    )
                notes.append(f"linear law v = L z: {gs.how}")
                if gs.vertices and len(gs.vertices) > 1:
                    vs_txt = "; ".join(
                        str(np.asarray(po.qfloat(v)).round(4).reshape(-1).tolist())
                        for v in gs.vertices
                    )
                    notes.append(
                        f"admissible linear gains: the convex hull of {len(gs.vertices)} vertices ({vs_txt}); dimension {gs.dimension}"
                    )
                for i, Lp in gs.prop71:
                    notes.append(
                        f"Proposition 7.1 with Q_I = row {i} of G gives L = {np.asarray(po.qfloat(Lp)).round(4).reshape(-1).tolist()}"
                    )
            else:
                notes.append(f"no linear law: {gs.how}")
                if not single:
                    params["contractivity_14"] = history[-1]["eps"] if history else None
        if o.L is not None:
            params["L_user"] = o.L
        params["history_facets"] = [h["facets"] for h in history]
        params["history_eps"] = [h["eps"] for h in history]
        solver = {
            "name": "HiGHS (scipy) LPs + qhull hulls; "
            + ("cdd.gmp exact" if exact_mode else "float64 only (no cdd.gmp)"),
            "status": "converged" if converged else "not converged",
            "seconds": round(time.perf_counter() - t0, 4),
        }
        if not exact_mode:
            notes.append(numerical.NOTE)
        return Design(params, solver, notes)

    # -- certificate ------------------------------------------------------------------------
    def certify(self, spec: Spec, params: Parameters) -> list[Claim]:
        o: Options = spec.options
        s = spec.system
        data = build(spec)
        ex = data.ex
        if ex is None:  # no cdd.gmp: the same claims in float64, status numerical
            return numerical.certify(spec, params, data.fl, REF)
        claims: list[Claim] = []
        G = exact_param(params, "G", claims, accept_float=False)
        if G is None:
            return claims
        G = np.asarray(G, dtype=object).reshape(-1, s.n)
        lam_r = params.get("lambda")
        if lam_r is None or not isinstance(lam_r, fmpq) or lam_r != o.lam:
            claims.append(
                exact_claim(
                    "lambda-matches-spec",
                    "the report's λ is the spec's λ",
                    "spec [method].lambda",
                    "exact equality",
                    0,
                    False,
                    f"report λ = {lam_r}, spec λ = {o.lam}",
                )
            )
        Vr = exact_param(params, "V", claims, accept_float=False)
        if Vr is None:
            return claims
        Vr = np.asarray(Vr, dtype=object).reshape(-1, s.n)
        bounded, detail, vrep = po.exact_check_forms(G, Vr)
        claims.append(
            exact_claim(
                "polyhedron-forms",
                "{e : G e <= 1} = conv(V): a bounded polytope with the origin inside, given by its facets G and vertices V",
                f"{REF}, Section III",
                "exact hull of V (cdd.gmp) has exactly the rows of G; every point of V is a vertex",
                0,
                bounded,
                detail,
            )
        )
        if not bounded or vrep is None:
            return claims
        ok, m = ce.omega_contained(G, ex.Vo)
        claims.append(
            exact_claim(
                "omega-contained",
                "Ω ⊆ {e : G e <= 1}",
                f"{REF}, Section V (C^0 = Ω ⊆ C^i)",
                "G e <= 1 at every exact vertex of Ω",
                0,
                ok,
                f"max G_i e over Ω's vertices = {float(m):.9g}",
            )
        )
        ok, m = necessary_condition(G, ex.B1, ex.Dv, ex.lam)
        claims.append(
            exact_claim(
                "necessary-condition",
                "λ·{G e <= 1} ⊇ B1·D (necessary condition of Section II)",
                f"{REF}, Section II",
                "max over D's vertices of G_i B1 d <= λ, exactly",
                0,
                ok,
                f"max = {float(m):.9g}, λ = {float(ex.lam):g}",
            )
        )
        if s.p == 1 and "breakpoints" in params and "v_breakpoints" in params:
            zs = list(np.asarray(params["breakpoints"], dtype=object).reshape(-1))
            vs = [
                list(r)
                for r in np.asarray(params["v_breakpoints"], dtype=object).reshape(len(zs), s.n)
            ]
            if not all(isinstance(x, fmpq) for x in zs) or not all(
                isinstance(x, fmpq) for r in vs for x in r
            ):
                claims.append(
                    exact_claim(
                        "theorem-3.1",
                        "Theorem 3.1",
                        REF,
                        "exact",
                        0,
                        False,
                        "breakpoints / v_breakpoints are not exact",
                    )
                )
                return claims
            res = ce.theorem31(ex, G, vs=vs, zs_given=zs, vrep=vrep)
            # float twin of the same inequality (exit 4 vs 1 when the exact check fails)
            flo = bool(float(res.factor) <= float(ex.lam) * (1 + 1e-9)) if res.eps else False
            det = (
                f"max over {len(res.zs)} breakpoints of max_i(φ_i(z) + G_i v + δ_i) = {_short(res.factor)}{float(res.factor):.9g} "
                f"(λ = {float(ex.lam):g}); worst z = {float(res.zs[res.worst]):.6g}"
                if res.eps
                else "; ".join(res.notes)
            )
            claims.append(
                exact_claim(
                    "theorem-3.1",
                    f"{{G e <= 1}} is D-(C,A)-λ-contractive with λ = {ex.lam}: φ(z^l) + G v^l + δ <= λ·1 at every z^l ∈ Z_d",
                    f"{REF}, Theorem 3.1 and LPs (6), (9)",
                    "exact φ from the slice's exact vertices; exact δ from D's vertices; rational v^l",
                    0,
                    res.ok,
                    det,
                    None if res.ok else flo,
                )
            )
            if "contractivity" in params and res.eps:
                c = params["contractivity"]
                claims.append(
                    exact_claim(
                        "contractivity-value",
                        "the reported contractivity equals the certified factor max_l max_i(φ_i + G_i v^l + δ_i)",
                        f"{REF}, Theorem 3.1",
                        "exact equality",
                        0,
                        isinstance(c, fmpq) and c == res.factor,
                        f"reported {_short(c)}{float(c) if isinstance(c, fmpq) else c}, recomputed {_short(res.factor)}{float(res.factor):.12g}",
                    )
                )
            if "L_pieces" in params and "w_pieces" in params:
                Ls, ws = laws.pieces(zs, vs)
                okp = np.array_equal(
                    np.asarray(params["L_pieces"], dtype=object).reshape(-1),
                    np.array(Ls, dtype=object).reshape(-1),
                ) and np.array_equal(
                    np.asarray(params["w_pieces"], dtype=object).reshape(-1),
                    np.array(ws, dtype=object).reshape(-1),
                )
                claims.append(
                    exact_claim(
                        "injection-table",
                        "L^j, w^j are the interpolation (12) of the certified v^j: L^j = (v^{j+1} − v^j)/(z^{j+1} − z^j), w^j = v^j − z^j L^j",
                        f"{REF}, Proposition 4.1",
                        "exact recomputation",
                        0,
                        okp,
                        f"{len(Ls)} segments",
                    )
                )
        elif s.p == 1:
            claims.append(
                exact_claim(
                    "theorem-3.1",
                    "Theorem 3.1",
                    REF,
                    "exact",
                    0,
                    False,
                    "the report has no breakpoint table",
                )
            )
        for key, label in (("L", "designed"), ("L_user", "given in the spec")):
            if key in params:
                L = exact_param(params, key, claims, accept_float=False)
                if L is None:
                    continue
                L = np.asarray(L, dtype=object).reshape(s.n, s.p)
                okL, f = ce.linear_law(ex, G, vrep.V, L)
                claims.append(
                    exact_claim(
                        f"linear-law{'-user' if key == 'L_user' else ''}",
                        f"the linear injection v = L z ({label}) keeps {{G e <= 1}} λ-contractive: |G(A + L C) e + G L η| + δ <= λ",
                        f"{REF}, Proposition 7.1",
                        "exact, at every vertex e and noise vertex η",
                        0,
                        okL,
                        f"certified factor {float(f):.9g} (λ = {float(ex.lam):g})",
                        None if okL else bool(float(f) <= float(ex.lam) * (1 + 1e-9)),
                    )
                )
        if o.L is not None and "L_user" not in params:
            claims.append(
                exact_claim(
                    "linear-law-user",
                    "the spec's L is checked",
                    REF,
                    "presence",
                    0,
                    False,
                    "the report lacks L_user",
                )
            )
        if s.p != 1 and "L" not in params:
            claims.append(
                exact_claim(
                    "linear-law",
                    "a linear injection keeps the polyhedron λ-contractive (Proposition 7.1)",
                    f"{REF}, Proposition 7.1",
                    "exact",
                    0,
                    False,
                    "no admissible linear gain was found",
                )
            )
        if params.get("converged") is False:
            claims.append(
                exact_claim(
                    "converged",
                    "the algorithm converged within max_iterations",
                    f"{REF}, Sections V-VI",
                    "iteration count",
                    0,
                    False,
                    f"not converged after {params.get('iterations')} iterations",
                    False,
                )
            )
        return claims

    # -- simulation -------------------------------------------------------------------------
    def simulate(self, spec: Spec, params: Parameters, **kwargs: Any) -> Any:
        from .sim import simulate

        return simulate(spec, params, **kwargs)

    def plot_simulation(self, spec: Spec, res: Any, path: Any) -> Any:
        from .plots import plot_simulation

        return plot_simulation(spec, res, path)

    def plot_design(self, spec: Spec, params: Parameters, path: Any) -> Any:
        from .plots import plot_design

        return plot_design(spec, params, path)

    def summary(self, params: Parameters) -> str:
        out = f"{params.get('facets')} facets, {params.get('iterations')} iterations"
        if "contractivity" in params:
            out += f", certified factor {params.float('contractivity'):.9g}"
        if "L" in params:
            out += f", linear L = {np.round(params.float('L').reshape(-1), 4).tolist()}"
        return out

    def template(self) -> str:
        from .template import TEMPLATE

        return TEMPLATE

    def options_schema(self) -> dict[str, Any]:
        num = {"type": "number"}
        mat = {"type": "array", "items": {"anyOf": [num, {"type": "array", "items": num}]}}
        return {
            "type": "object",
            "required": ["key", "omega", "lambda"],
            "additionalProperties": False,
            "properties": {
                "key": {"const": self.key},
                "omega": {
                    "type": "string",
                    "description": "name of the initial-error set Ω in [sets]",
                },
                "disturbance": {
                    "type": "string",
                    "description": "name of the disturbance set D in [sets]",
                },
                "eta_bar": {**num, "minimum": 0},
                "lambda": {**num, "exclusiveMinimum": 0, "maximum": 1},
                "algorithm": {"enum": list(ALGORITHMS)},
                "delta_tol": {**num, "exclusiveMinimum": 0},
                "max_iterations": {"type": "integer", "minimum": 1},
                "mirror": {"type": "boolean"},
                "strict": {"type": "boolean"},
                "fallback": {"enum": ["general", "none"]},
                "L": mat,
                "linear_law": {"type": "boolean"},
            },
        }


def _parse_disturbance(table: Table, spec: Spec) -> tuple[str | None, Any]:
    """``disturbance``: the name of a set in [sets] (when its dimension is n) or an inline
    table ``{type = "box", lower, upper}`` / ``{type = "polytope", G, g}`` of dimension
    = columns of B1 (the [sets] loader requires state dimension)."""
    from obsdesign.sets.polytope import check_polytope_q

    s = spec.system
    if not table.has("disturbance"):
        if s.nd > 0:
            raise table.error(
                "disturbance",
                f"expected the disturbance set D of dimension {s.nd} (the system has B1)",
            )
        return None, None
    raw = table.data["disturbance"]
    if isinstance(raw, str):
        name = table.str("disturbance")
        if name not in spec.sets:
            raise table.error("disturbance", f"expected the name of a set in [sets]; got {name!r}")
        D = spec.sets[name]
        if not isinstance(D, (Box, Polytope)):
            raise table.error("disturbance", "expected a box or polytope set for D")
    else:
        t = table.table("disturbance")
        assert t is not None
        kind = t.str("type", choices=("box", "polytope"))
        if kind == "box":
            lo, hi = t.vector("lower", n=s.nd), t.vector("upper", n=s.nd)
            if any(not lo.q[i] <= hi.q[i] for i in range(s.nd)):
                raise t.error("upper", "expected lower <= upper in every coordinate")
            D = Box(lo.q, hi.q)
        else:
            Gd = t.matrix("G", cols=s.nd)
            gd = t.vector("g", n=Gd.shape[0])
            D = Polytope(Gd.q, np.asarray(gd.q, dtype=object))
            nonempty, bounded, _exact = check_polytope_q(D.G_q, D.g_q)
            if not (nonempty and bounded):
                raise t.error("G", "expected a bounded, non-empty polytope D")
        t.done()
        name = "disturbance"
    if D.dim != s.nd:
        raise table.error(
            "disturbance", f"expected a set of dimension {s.nd} (columns of B1), got {D.dim}"
        )
    return name, D


def SpecErrorAt(spec: Spec, key: str, expected: str) -> Exception:  # noqa: N802
    from obsdesign.errors import SpecError

    return SpecError(spec.file, key, expected)


def _short(x: Any) -> str:
    """``"p/q ≈ "`` when the exact value is short enough to print, else ``"≈ "``."""
    t = str(x)
    return f"{t} ≈ " if len(t) <= 24 else "≈ "


def infeasible(msg: str) -> InfeasibleError:
    return InfeasibleError(msg)


METHOD = SetInvariant()
