"""verification_tables - the verification page's tables, computed at every docs build.

Input : the compiled solvers (``rockfrag.models.simulate``) and the verification tests' own closed forms,
        independent scipy references and cases (``tests/physics``: imported, not copied).
Output: ``page()``, MyST markdown: one table per check with the exact or reference value, rockfrag's value and
        their relative difference, and the test that asserts it in ``make test``.

The cases are a few of each test's own (the cheap ones: the whole page takes a few seconds); the tests run them
all with their tolerances. Nothing here is typed by hand but the words: a changed solver changes the numbers.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from rockfrag.models import simulate

G = 9.80665


def _relative(value: float, exact: float) -> str:
    return f"{abs(value - exact) / abs(exact):.1e}"


def _table(header: list[str], rows: list[list[object]]) -> str:
    from rockfrag_docs import table

    return table(header, rows)


def _section(title: str, text: str, header: list[str], rows: list[list[object]], tests: str) -> str:
    return f"# {title}\n\n{text}\n\n{_table(header, rows)}\nChecked in `make test` by {tests}.\n"


def housner_free_rocking() -> str:
    """Impact times of free rocking (r = 1) against the exact elliptic-integral quarter period."""
    from tests.physics.test_housner_closed_form import BLOCK, quarter_period_elliptic

    rows = []
    for ratio in (0.05, 0.5, 0.95):
        theta0 = ratio * BLOCK.alpha
        result = simulate("housner", np.zeros(2), 1e-3, BLOCK, theta0=theta0, restitution=1.0, t_end=12.0,
                          rtol=1e-10, atol=1e-10)
        exact = quarter_period_elliptic(theta0)
        rows.append([f"θ₀ = {ratio}α", f"{exact:.9f}", f"{result.impact_times[0]:.9f}",
                     _relative(result.impact_times[0], exact)])
    return _section(
        "Housner: free rocking against the exact period",
        f"A block of R = {BLOCK.R:g} m, α = {BLOCK.alpha:g} rad released from rest at θ₀ without impact losses "
        "(r = 1): the time to the first impact is a quarter period, an incomplete elliptic integral.",
        ["release", "exact [s]", "rockfrag [s]", "relative difference"], rows,
        "`tests/physics/test_housner_closed_form.py::test_free_rocking_impact_times_match_exact_period`")


def housner_impacts() -> str:
    """Amplitude after each impact against the energy balance with Housner's r."""
    from tests.physics.test_housner_closed_form import BLOCK

    alpha, r = BLOCK.alpha, BLOCK.housner_restitution()
    theta0 = 0.8 * alpha
    result = simulate("housner", np.zeros(2), 2e-4, BLOCK, theta0=theta0, t_end=6.0)
    rows, amplitude = [], theta0
    for n in range(min(4, result.n_impacts)):
        expected = alpha - math.acos(math.cos(alpha) + r**2 * (math.cos(alpha - amplitude) - math.cos(alpha)))
        start = result.impact_times[n]
        end = result.impact_times[n + 1] if n + 1 < result.n_impacts else result.t[-1]
        window = np.flatnonzero((result.t > start) & (result.t < end))
        index = window[np.argmax(np.abs(result.theta[window]))]
        y0, y1, y2 = np.abs(result.theta[index - 1:index + 2])
        peak = y1 - (y0 - y2) ** 2 / (8 * (y0 - 2 * y1 + y2))  # vertex of the parabola through the samples
        rows.append([n + 1, f"{expected:.8f}", f"{peak:.8f}", _relative(peak, expected)])
        amplitude = expected
    return _section(
        "Housner: the amplitude after each impact",
        f"Released at θ₀ = 0.8α with Housner's r = {r:.6f}: after impact n the next amplitude obeys "
        "cos(α − θₙ₊₁) = cos α + r²(cos(α − θₙ) − cos α).",
        ["impact", "exact θ [rad]", "rockfrag θ [rad]", "relative difference"], rows,
        "`tests/physics/test_housner_closed_form.py::test_amplitude_after_each_impact`")


def housner_pulse() -> str:
    """The shortest rectangular pulse that overturns the block, exact and found by bisection on the solver."""
    from tests.physics.test_housner_closed_form import BLOCK, critical_pulse_duration

    dt = 1e-4
    rows = []
    for factor in (1.5, 3.0):
        amplitude = factor * G * math.tan(BLOCK.alpha)
        exact = critical_pulse_duration(amplitude)

        def overturns(samples):
            ag = np.zeros(samples + 2)
            ag[:samples + 1] = -amplitude
            return simulate("housner", ag, dt, BLOCK, t_end=8.0).overturned

        low, high = int(0.9 * exact / dt), int(1.1 * exact / dt)
        assert not overturns(low) and overturns(high), "the bracket must hold the threshold"
        while high - low > 1:
            middle = (low + high) // 2
            low, high = (low, middle) if overturns(middle) else (middle, high)
        # the last sample interval ramps down: the pulse's impulse is that of a rectangle dt/2 longer
        found = high * dt + dt / 2
        rows.append([f"{factor} g tan α", f"{exact:.5f}", f"{found:.5f}", _relative(found, exact)])
    return _section(
        "Housner: the overturning threshold of a rectangular pulse",
        f"The shortest pulse of a given amplitude that overturns the block, exact (an energy integral) and found "
        f"by bisection on the solver to the record's step ({dt:g} s).",
        ["amplitude", "exact duration [s]", "rockfrag [s]", "relative difference"], rows,
        "`tests/physics/test_housner_closed_form.py::test_rectangular_pulse_overturning_threshold`")


def ssi_stiff_limit() -> str:
    """The paper's model tends to Housner's as the spring stiffens."""
    from tests.physics.test_ssi_stiff_limit import free, second_peak, stiffness

    housner = free("housner")
    rows, previous = [], None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # the spring pulls in free rocking: the test ignores it too
        for ratio in (50, 100, 200, 400):
            ssi = free("ssi", k=stiffness(ratio), xi=0.05, switch="consistent")
            error = abs(ssi.impact_times[1] - housner.impact_times[1]) / housner.impact_times[1]
            peak_error = abs(second_peak(ssi) - second_peak(housner)) / second_peak(housner)
            rows.append([ratio, f"{error:.2e}", f"{peak_error:.2e}",
                         f"{previous / error:.2f}" if previous else ""])
            previous = error
    return _section(
        "SSI-rocking tends to Housner on stiff ground",
        "Free rocking of the paper's model (`ssi`, pivot switch `consistent`, ξ = 0.05) against Housner's block "
        "with its restitution, as the spring's frequency ω grows against Housner's p: the error halves (or "
        "better) with each doubling.",
        ["ω/p", "2nd impact time, relative error", "2nd amplitude, relative error", "error ratio to the row above"],
        rows, "`tests/physics/test_ssi_stiff_limit.py::test_stiff_foundation_converges_to_housner`")


def against_references() -> str:
    """The compiled kernels against the tests' independent scipy references on a real record."""
    from tests.physics.motions import BLOCK, TAIL, case_motion
    from tests.physics.reference import reference_response
    from tests.physics.winkler_reference import reference_winkler

    rows = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        for model, omega_over_p in (("housner", None), ("ssi", 30.0), ("winkler", 30.0)):
            ag, dt = case_motion("DUZCE/BOL090", 3.0)
            t_end = (ag.size - 1) * dt + TAIL
            k = BLOCK.mass * (omega_over_p * BLOCK.p()) ** 2 if omega_over_p else None
            if model == "winkler":
                reference = reference_winkler(ag, dt, BLOCK.b, BLOCK.h, BLOCK.mass, k, 0.05, "two-spring",
                                              t_end=t_end)
                result = simulate(model, ag, dt, BLOCK, k=k, xi=0.05, bed="two-spring", t_end=t_end)
                peak = reference["peak_angle"]
                also = f"peak corner uplift {reference['peak_uplift'] * 1e3:.4f} / {result.peak_uplift * 1e3:.4f} mm"
                label = f"winkler (two-spring bed, ω_v/p = {omega_over_p:g})"
            else:
                peak, impact_times, _ = reference_response(model, ag, dt, BLOCK, k=k, xi=0.05, t_end=t_end)
                result = simulate(model, ag, dt, BLOCK, k=k, xi=0.05, t_end=t_end)
                also = f"impacts {len(impact_times)} / {result.n_impacts}"
                label = model if omega_over_p is None else f"{model} (ω/p = {omega_over_p:g})"
            rows.append([label, f"{peak:.8f}", f"{result.peak_angle:.8f}", _relative(result.peak_angle, peak), also])
    return _section(
        "The kernels against independent references on a real record",
        f"Bolu 090 (1999 Düzce), its first {ag.size * dt:g} s scaled to 3 times the uplift PGA of a block of "
        f"R = {BLOCK.R:g} m, α = {BLOCK.alpha:g} rad, then {TAIL:g} s of free motion. The references are written "
        "independently of the kernels (scipy `solve_ivp`, DOP853 at a relative tolerance of 10⁻¹⁰, one solve per "
        "straight piece of the ground motion, events at every impact and contact change); rockfrag runs at its "
        "default tolerance (10⁻⁶).",
        ["model", "reference peak θ [rad]", "rockfrag peak θ [rad]", "relative difference",
         "also compared (reference / rockfrag)"], rows,
        "`tests/physics/test_kernels_vs_scipy.py` and `tests/physics/test_winkler_vs_reference.py` (more records, "
        "scales, stiffnesses and both beds)")


def sliding_newmark() -> str:
    """Slip of a squat block under a rectangular pulse against Newmark's rigid-plastic block."""
    from tests.physics.test_sliding_closed_forms import SQUAT, newmark_slip, rectangular_pulse

    rows = []
    for friction in (0.3, (0.5, 0.2)):
        mu_k = friction if isinstance(friction, float) else friction[1]
        for amplitude_g in (0.6, 1.0):
            amplitude = amplitude_g * G
            ag, duration = rectangular_pulse(amplitude, 0.5, 1e-4)
            result = simulate("housner", ag, 1e-4, SQUAT, friction=friction, t_end=3.0)
            exact = newmark_slip(amplitude, duration, mu_k)
            rows.append([f"μ = {friction}", f"{amplitude_g} g", f"{exact:.7f}", f"{result.peak_slip:.7f}",
                         _relative(result.peak_slip, exact)])
    return _section(
        "Sliding: Newmark's block",
        "A squat block (b/h = 2, far above μ: it slides and never rocks) under a rectangular pulse of 0.5 s on the "
        "rigid base, against Newmark's (1965) closed-form slip of a rigid-plastic block. μ is one coefficient or "
        "(static, kinetic).",
        ["friction", "pulse", "exact slip [m]", "rockfrag slip [m]", "relative difference"], rows,
        "`tests/physics/test_sliding_closed_forms.py::test_rectangular_pulse_rigid_base_matches_newmark`")


SECTIONS = (housner_free_rocking, housner_impacts, housner_pulse, ssi_stiff_limit, against_references,
            sliding_newmark)


def page() -> str:
    """Every table of the verification page, computed now."""
    return "\n".join(section() for section in SECTIONS)
