"""Where a Newton iteration of the FEM spends its time, and what the step control saves.

Three measurements behind the solver's design choices (one thread):

``assembly``
    Hessian assembly time of each energy term of one design (default: the
    largest corner), mean of repeats at a perturbed state, interpreted and
    compiled to machine code (``softbend.fem.use_compiled``; the compilation
    itself, about 30 CPU seconds, is not timed). Also timed, for
    comparison: gravity as a twice-differentiated ``Variation`` term (softbend
    assembles it once as a dead-load vector instead), and two other ways to
    give NGSolve the elastomer's tangent — the first variation ``P:∇v`` with
    NGSolve's linearisation, the tangent ``∂P/∂F`` written out with ``Diff``
    as a linear form, and a 9×9 tangent as the coefficient of a compiled
    bilinear form (constant, or read from an element-wise GridFunction), beside
    ``∫∇u:∇v`` on the same space.

``steps``
    Six slow corner designs swept to 0.5 MPa / 300° with the pressure step sized
    by the predictor's miss (softbend's rule) and with the earlier rule (grow
    1.5× after a step of at most five Newton iterations, shrink 0.7× after nine
    or more); prints Newton iterations and rejected steps. Iteration counts do
    not depend on the machine's speed, so the two rules may run side by side.

``rtol``
    Four designs (two slow corners, the reference design (140, 8, 3, 3, 10,
    10) and (100, 6, 2, 2, 5, 8)) swept with Newton tolerances looser than the
    default 1e-9: Newton iterations, load steps, rejected steps and the largest
    change of an output angle against the default. Iteration counts do not
    depend on the machine's speed.

::

    python benchmarks/bench_fem_solver.py assembly
    python benchmarks/bench_fem_solver.py steps
    python benchmarks/bench_fem_solver.py rtol
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _record import record as record_figures
from _record import variant_name

import softbend.fem  # noqa: F401  (loads PyTorch before NGSolve)
from softbend.campaign.backends import default_pressures_mpa
from softbend.design import parse_sfrba
from softbend.fem import FEMOptions, simulate, sweep, use_compiled
from softbend.fem.actuator import ActuatorModel
from softbend.fem.mechanics import solid_energy

SLOW_CORNERS = (
    "160,10,4,2,15,8",
    "160,10,4,2,5,12",
    "160,10,4,2,5,8",
    "160,10,2,2,15,12",
    "100,6,4,4,15,12",
    "160,6,2,2,5,8",
)


def _mean_time(action, repeats: int) -> float:
    action()  # first call allocates the matrix
    start = time.perf_counter()
    for _ in range(repeats):
        action()
    return (time.perf_counter() - start) / repeats


def assembly(design: str, repeats: int) -> dict:
    import ngsolve as ngs

    model = ActuatorModel(parse_sfrba(design), FEMOptions())
    rng = np.random.default_rng(0)
    model.set_state(0.01 * rng.standard_normal(model.state().shape) * model.solver.free_mask)
    model.set_load(0.05, 1.0)
    vec = model.gfu.vec
    print(f"design {design}: {model.ndof} unknowns, {model.n_elements} tetrahedra")

    def linearization_time(*terms) -> float:
        form = ngs.BilinearForm(model.fes, symmetric=True)
        for term in terms:
            form += term
        return _mean_time(lambda: form.AssembleLinearization(vec), repeats)

    names = ("elastomer (volume)", "layer membrane", "fibers", "pressure")
    terms = list(model.form.integrators)
    together = linearization_time(*terms)
    print(f"  all terms together: {together:.3f} s")
    figures = {"Hessian assembly, all terms, interpreted": round(1e3 * together, 1)}
    for name, term in zip(names, terms, strict=True):
        print(f"  {name}: {linearization_time(term):.3f} s")

    # The same terms compiled to machine code (softbend.fem.energy), same state.
    use_compiled(True, wait=True)
    try:
        fast = ActuatorModel(model.design, model.options)
    finally:
        use_compiled(False)
    fast.set_state(model.state())
    fast.set_load(0.05, 1.0)
    print("  compiled (use_compiled), Hessian assembly interpreted -> compiled:")
    for name, slow_term, fast_term in zip(names, terms, fast.form.integrators, strict=True):
        slow, quick = linearization_time(slow_term), linearization_time(fast_term)
        print(f"    {name}: {1e3 * slow:.1f} -> {1e3 * quick:.1f} ms")
        figures[f"{name}, interpreted"] = round(1e3 * slow, 1)
        figures[f"{name}, compiled"] = round(1e3 * quick, 1)
    residual = vec.CreateVector()
    slow_s = _mean_time(lambda: model.form.Apply(vec, residual), repeats)
    fast_s = _mean_time(lambda: fast.form.Apply(vec, residual), repeats)
    print(f"    residual, all terms: {1e3 * slow_s:.1f} -> {1e3 * fast_s:.1f} ms")
    figures["residual, all terms, interpreted"] = round(1e3 * slow_s, 1)
    figures["residual, all terms, compiled"] = round(1e3 * fast_s, 1)

    u, v = model.fes.TnT()
    g = ngs.CoefficientFunction(model._gravity_vector())
    rho = model.options.elastomer.density_t_per_mm3
    gravity = ngs.Variation(-rho * ngs.InnerProduct(g, u) * ngs.dx)
    print(f"  gravity as a Variation term (not used): {linearization_time(gravity):.3f} s")

    o = model.options
    bulk = o.bulk_ratio * o.elastomer.model.initial_shear_modulus_mpa
    F = ngs.Id(3) + ngs.Grad(u)
    stress = solid_energy(F, o.elastomer.model, bulk).Diff(ngs.Grad(u))
    first = ngs.BilinearForm(model.fes, symmetric=True)
    first += ngs.InnerProduct(stress, ngs.Grad(v)).Compile() * ngs.dx
    seconds = _mean_time(lambda: first.AssembleLinearization(vec), repeats)
    print(f"  elastomer as first variation P:grad v (not used): {seconds:.3f} s")

    Fg = ngs.Id(3) + ngs.Grad(model.gfu)
    Pg = solid_energy(Fg, o.elastomer.model, bulk).Diff(Fg)
    tangent = ngs.BilinearForm(model.fes, symmetric=True)
    tangent += ngs.InnerProduct(Pg.Diff(Fg, ngs.Grad(u)), ngs.Grad(v)).Compile() * ngs.dx
    seconds = _mean_time(tangent.Assemble, max(1, repeats // 3))
    print(f"  elastomer tangent dP/dF written with Diff (not used): {seconds:.3f} s")

    # A 9x9 material tangent handed to NGSolve as a coefficient of an ordinary
    # bilinear form, compiled (not used): a constant one is the ceiling of what
    # that could save; an element-wise GridFunction is what a tangent computed
    # outside NGSolve would be read from.
    grad_u, grad_v = ngs.Grad(u).Reshape((9,)), ngs.Grad(v).Reshape((9,))
    constant = ngs.CoefficientFunction(tuple((np.eye(9) + 0.1).ravel()), dims=(9, 9))
    stored = ngs.GridFunction(ngs.L2(model.mesh, order=0, dim=81))
    stored.vec[:] = 1.0
    element_wise = ngs.InnerProduct(stored.Reshape((9, 9)) * grad_u, grad_v)
    laplace = ngs.InnerProduct(ngs.Grad(u), ngs.Grad(v))
    for name, integrand in (
        ("constant 9x9 tangent", ngs.InnerProduct(constant * grad_u, grad_v)),
        ("9x9 tangent from an element-wise GridFunction", element_wise),
        ("grad u : grad v", laplace),
    ):
        form = ngs.BilinearForm(model.fes, symmetric=True)
        form += integrand.Compile(realcompile=True, wait=True) * ngs.dx
        seconds = _mean_time(form.Assemble, repeats)
        print(f"  {name}, compiled bilinear form (not used): {1e3 * seconds:.1f} ms")
    return figures


def _iteration_rule() -> None:
    """Replace the step control by the earlier rule on Newton's iteration count."""
    record, last = sweep._record, {"iterations": 0}

    def recording(model, pressure, iterations, keep_state):
        last["iterations"] = iterations
        return record(model, pressure, iterations, keep_state)

    def by_iterations(dp, miss_mm, options):
        if last["iterations"] <= 5:
            return min(options.max_step_mpa, 1.5 * dp)
        if last["iterations"] >= 9:
            return max(options.min_step_mpa, 0.7 * dp)
        return dp

    sweep._record, sweep._next_step = recording, by_iterations


def steps(rule: str) -> dict:
    if rule == "iterations":
        _iteration_rule()
    total_iterations = total_rejected = 0
    for design in SLOW_CORNERS:
        result = simulate(parse_sfrba(design), default_pressures_mpa(), FEMOptions())
        iterations = int(result.stats["timings"]["iterations"])
        rejected = int(result.stats["rejected_steps"])
        total_iterations += iterations
        total_rejected += rejected
        print(f"  {design:<18} {iterations:4d} Newton iterations, {rejected} rejected steps")
    print(f"step rule '{rule}': {total_iterations} Newton iterations, {total_rejected} rejected")
    return {
        f"step rule '{rule}': Newton iterations": total_iterations,
        f"step rule '{rule}': rejected steps": total_rejected,
    }


RTOL_DESIGNS = ("160,6,2,2,5,8", "100,6,2,2,5,8", "140,8,3,3,10,10", "160,10,4,2,15,8")


def rtol(values: tuple[float, ...] = (1e-9, 3e-9, 1e-8)) -> dict:
    totals = dict.fromkeys(values, 0)
    for design in RTOL_DESIGNS:
        reference = None
        for value in values:
            result = simulate(parse_sfrba(design), default_pressures_mpa(), FEMOptions(rtol=value))
            iterations = int(result.stats["timings"]["iterations"])
            totals[value] += iterations
            line = (
                f"  {design:<18} rtol {value:.0e}: {iterations:4d} Newton iterations, "
                f"{len(result.stats['steps_mpa'])} steps, {result.stats['rejected_steps']} "
                f"rejected, {len(result.angle_deg)} outputs"
            )
            if reference is None:
                reference = result
            else:
                n = min(len(reference.angle_deg), len(result.angle_deg))
                change = np.abs(result.angle_deg[:n] - reference.angle_deg[:n])
                line += f", largest angle change {np.nanmax(change):.4f} deg"
            print(line)
    summary = ", ".join(f"{v:.0e}: {n}" for v, n in totals.items())
    print(f"Newton iterations, all designs: {summary}")
    return {f"rtol {v:.0e}: Newton iterations, all designs": n for v, n in totals.items()}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("what", choices=("assembly", "steps", "rtol"))
    parser.add_argument("--design", default="160,10,4,2,5,12", help="For 'assembly'.")
    parser.add_argument("--repeats", type=int, default=6, help="For 'assembly'.")
    parser.add_argument(
        "--rule", choices=("miss", "iterations", "both"), default="both", help="For 'steps'."
    )
    args = parser.parse_args(argv)
    from ngsolve import SetNumThreads, TaskManager

    SetNumThreads(1)
    figures: dict = {}
    with TaskManager():
        if args.what == "assembly":
            figures = assembly(args.design, args.repeats)
        elif args.what == "rtol":
            use_compiled(True, wait=True)
            figures = rtol()
        else:
            for rule in ("miss", "iterations") if args.rule == "both" else (args.rule,):
                figures.update(steps(rule))
    note = f"design {args.design}, mean of {args.repeats}" if args.what == "assembly" else ""
    units = dict.fromkeys(figures, "ms") if args.what == "assembly" else {}
    name = variant_name("fem_solver", args.what)
    record_figures(name, figures, units=units, notes=f"one thread; {note}".rstrip("; "))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
