"""rockfrag.lognormal_fit - lognormal fragility fits on arrays (no cube, no xarray).

Input : counts per intensity level (exceed, total : (..., n_level)) and the levels [IM units], or
        per-record capacities [IM units] with right-censoring.
Output: median [IM units] and dispersion beta [-] (beta = 0: a step), deviance and goodness of fit.

Binomial maximum likelihood (Baker 2015, Earthquake Spectra 31(1)) as a probit regression solved by
Fisher scoring on whole stacks of data sets at once (bootstrap samples x damage states); one slope per
group gives the shared-beta fit of ordered states. Perfectly separated counts have no lognormal MLE
(the likelihood grows as beta -> 0): they are detected first and reported as a step.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize
from scipy.special import log_ndtr, ndtr, ndtri
from scipy.stats import chi2

CROSSING_TOLERANCE = 1e-3
"""Two fitted curves cross when the less severe one falls below the more severe one by more than this."""


# ---------------------------------------------------------------- binomial (probit) maximum likelihood

#
# P(DS | im) = Phi((ln im - ln median) / beta) = Phi(a + c x) with x = ln im, c = 1/beta, a = -c ln median:
# a probit regression. Fisher scoring with closed-form score and information converges in a handful of
# iterations and runs on whole stacks of data sets at once (bootstrap samples x damage states), so the
# bootstrap is a few array operations per cell instead of thousands of scipy.optimize calls.

MAX_ITERATIONS = 60
STEP_TOLERANCE = 1e-9


def _log_pdf(eta):
    return -0.5 * eta**2 - 0.5 * np.log(2 * np.pi)


def _log_likelihood(eta, exceed, total):
    """Binomial log-likelihood summed over levels; eta, exceed, total : (..., n_level)."""
    return np.sum(exceed * log_ndtr(eta) + (total - exceed) * log_ndtr(-eta), axis=-1)


def _score_and_weight(eta, exceed, total):
    """The score d loglik / d eta and the Fisher weight n phi^2 / (Phi (1 - Phi)), computed in logs (tails)."""
    log_phi = _log_pdf(eta)
    low, high = log_ndtr(eta), log_ndtr(-eta)
    score = exceed * np.exp(log_phi - low) - (total - exceed) * np.exp(log_phi - high)
    weight = total * np.exp(2 * log_phi - low - high)
    return score, weight


def probit_mle(x, exceed, total, a0, c0):
    """Probit MLE with one intercept per state and one slope per group (shared beta).

    x : (n_level,) log intensities; exceed, total : (..., n_state, n_level) counts;
    a0 : (..., n_state) and c0 : (...,) starting values. Independent fits are groups of one state.
    Returns (a, c) of shapes (..., n_state) and (...,); c > 0.
    """
    a, c = np.array(a0, float), np.array(c0, float)
    n_state = exceed.shape[-2]
    eye = np.eye(n_state + 1)
    ll = _log_likelihood(a[..., None] + c[..., None, None] * x, exceed, total).sum(-1)
    for _ in range(MAX_ITERATIONS):
        eta = a[..., None] + c[..., None, None] * x
        score, weight = _score_and_weight(eta, exceed, total)
        gradient = np.concatenate([score.sum(-1), (score * x).sum((-1, -2))[..., None]], axis=-1)
        information = np.zeros(gradient.shape + (n_state + 1,))
        diagonal = weight.sum(-1)
        cross = (weight * x).sum(-1)
        for k in range(n_state):
            information[..., k, k] = diagonal[..., k]
            information[..., k, -1] = information[..., -1, k] = cross[..., k]
        information[..., -1, -1] = (weight * x**2).sum((-1, -2))
        information += 1e-12 * eye
        step = np.linalg.solve(information, gradient[..., None])[..., 0]
        scale = np.ones(c.shape)
        for _ in range(30):  # step halving where the likelihood would drop or beta turn negative
            a_new = a + scale[..., None] * step[..., :-1]
            c_new = c + scale * step[..., -1]
            ll_new = _log_likelihood(a_new[..., None] + np.maximum(c_new, 1e-12)[..., None, None] * x,
                                     exceed, total).sum(-1)
            bad = (c_new <= 0) | ~(ll_new >= ll - 1e-10)
            if not bad.any():
                break
            scale = np.where(bad, scale / 2, scale)
        a, c, ll = a_new, c_new, ll_new
        if np.nanmax(np.abs(scale[..., None] * step), initial=0.0) < STEP_TOLERANCE:
            break
    return a, c


def _starting_values(x, exceed, total):
    """Weighted least squares on the empirical probits of smoothed fractions: (a0, c0) per state."""
    fraction = (exceed + 0.5) / (total + 1.0)
    z = ndtri(fraction)
    w = np.where(total > 0, total * np.exp(2 * _log_pdf(z)) / (fraction * (1 - fraction)), 0.0)
    sw = w.sum(-1)
    mean_x = (w * x).sum(-1) / sw
    mean_z = (w * z).sum(-1) / sw
    slope = (w * (x - mean_x[..., None]) * (z - mean_z[..., None])).sum(-1) / (w * (x - mean_x[..., None]) ** 2).sum(-1)
    slope = np.clip(np.nan_to_num(slope, nan=2.5), 0.5, 50.0)
    return mean_z - slope * mean_x, slope


def separation(exceed, total):
    """Per data set (..., n_level): True where the counts are perfectly or quasi-completely separated.

    Separated means: every level below the first exceedance has none, every level above the last
    survivor is fully exceeded, and at most one level is mixed. The likelihood then grows as
    beta -> 0 and no lognormal MLE exists. Also returns the index of the first level with an
    exceedance and of the last level with a survivor.
    """
    has_data = total > 0
    some = has_data & (exceed > 0)
    not_all = has_data & (exceed < total)
    n = exceed.shape[-1]
    first_some = np.where(some.any(-1), np.argmax(some, -1), n)
    last_not_all = np.where(not_all.any(-1), n - 1 - np.argmax(not_all[..., ::-1], -1), -1)
    return (last_not_all <= first_some) & some.any(-1) & not_all.any(-1), first_some, last_not_all


def step_median(levels, exceed, total):
    """Median of a separated data set: the mixed level, or the geometric mean of the bracketing levels."""
    _, first_some, last_not_all = separation(exceed, total)
    has_data = total > 0
    mixed = first_some == last_not_all
    # bracket: last level with data and no exceedance, first level with data fully exceeded
    upper = levels[np.clip(first_some, 0, levels.size - 1)]
    lower_index = np.where(has_data[..., :] & (np.arange(levels.size) < first_some[..., None]),
                           np.arange(levels.size), -1).max(-1)
    lower = levels[np.clip(lower_index, 0, levels.size - 1)]
    return np.where(mixed, upper, np.sqrt(lower * upper))


def fit_binomial(im, exceed, total):
    """Lognormal fragility (median [IM units], beta [-]) by MLE on counts per level (Baker 2015).

    NaN, NaN when no level has an exceedance or every level is fully exceeded; (median, 0.0) for
    perfectly separated data (a step: no finite-beta MLE exists; see ``separation``).
    """
    im, exceed, total = (np.asarray(v, float) for v in (im, exceed, total))
    medians, betas = fit_independent(im, exceed[None], total[None])
    return float(medians[0]), float(betas[0])


def fit_independent(levels, exceed, total, start=None):
    """Vectorised ``fit_binomial`` over data sets exceed, total : (..., n_level).

    start : optional (median, beta) arrays of shape (...,) (warm start, e.g. the point estimate for
    bootstrap samples). Returns median, beta of shape (...,).
    """
    x = np.log(levels)
    shape = exceed.shape[:-1]
    median, beta = np.full(shape, np.nan), np.full(shape, np.nan)
    separated, *_ = separation(exceed, total)
    reached = ((exceed > 0) & (total > 0)).any(-1)
    not_everywhere = ((exceed < total) & (total > 0)).any(-1)
    regular = reached & not_everywhere & ~separated
    if separated.any():
        # a step between two levels, or at the one mixed level. A mixed level at the edge of the data brackets the
        # median only from its inner side: the lowest level with fewer than half the records in the state (every
        # record is at the next level up: the median lies between them), the highest with more than half (none
        # below it). On its outer side (the lowest with half or more, the highest with half or fewer), or with one
        # level of data, the step only says that the median lies outside the range: no estimate (NaN).
        _, first_some, last_not_all = separation(exceed, total)
        data_index = np.where(total > 0, np.arange(levels.size), -1)
        lowest = np.where(total > 0, np.arange(levels.size), levels.size).min(-1)
        highest = data_index.max(-1)
        mixed = np.clip(first_some, 0, levels.size - 1)
        with np.errstate(invalid="ignore", divide="ignore"):
            fraction = np.take_along_axis(exceed / total, mixed[..., None], -1)[..., 0]
        at_edge = (first_some == last_not_all) & (
            (lowest == highest) | ((first_some == lowest) & ~(fraction < 0.5))
            | ((first_some == highest) & ~(fraction > 0.5)))
        step = separated & ~at_edge
        median[step] = step_median(levels, exceed[step], total[step])
        beta[step] = 0.0
    if regular.any():
        e, t = exceed[regular][:, None, :], total[regular][:, None, :]
        if start is not None and np.isfinite(start[0][regular]).all() and (start[1][regular] > 0).all():
            c0 = 1.0 / start[1][regular]
            a0 = (-c0 * np.log(start[0][regular]))[:, None]
        else:
            a0, c0 = _starting_values(x, e, t)
            c0 = c0[:, 0]
        a, c = probit_mle(x, e, t, a0, c0)
        median[regular], beta[regular] = np.exp(-a[:, 0] / c), 1.0 / c
    return median, beta


def fit_shared_beta(im, exceed_by_state, total_by_state, start=None):
    """Joint MLE of one median per state and a common beta (non-crossing by construction).

    exceed_by_state, total_by_state : (..., n_state, n_level). Returns medians (..., n_state) (made
    non-decreasing in severity) and beta (...,).
    """
    levels = np.asarray(im, float)
    x = np.log(levels)
    exceed, total = np.asarray(exceed_by_state, float), np.asarray(total_by_state, float)
    if start is None:
        a0, c0 = _starting_values(x, exceed, total)
        c0 = np.median(c0, axis=-1)
    else:
        medians0, beta0 = start
        c0 = 1.0 / np.asarray(beta0, float)
        a0 = -c0[..., None] * np.log(medians0)
    a, c = probit_mle(x, exceed, total, a0, c0)
    medians = np.maximum.accumulate(np.exp(-a / c[..., None]), axis=-1)
    return medians, 1.0 / c


def deviance(levels, exceed, total, median, beta):
    """Binomial deviance 2 (loglik_saturated - loglik) of a curve; a step where beta == 0."""
    p = np.clip(lognormal_cdf(levels, median, beta), 1e-300, 1.0)
    q = np.clip(1.0 - lognormal_cdf(levels, median, beta), 1e-300, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        term1 = np.where(exceed > 0, exceed * np.log(exceed / (total * p)), 0.0)
        term2 = np.where(total - exceed > 0, (total - exceed) * np.log((total - exceed) / (total * q)), 0.0)
    return float(2 * np.sum(np.where(total > 0, term1 + term2, 0.0)))


def lognormal_cdf(im, median, beta):
    """P(DS | im) of a lognormal fragility; a step at the median where beta == 0."""
    im, median, beta = (np.asarray(v, float) for v in (im, median, beta))
    with np.errstate(divide="ignore", invalid="ignore"):
        smooth = ndtr(np.log(im / median) / beta)
    return np.where(beta == 0, (im >= median).astype(float), smooth)


def fit_censored_capacities(capacities, censor_at):
    """Lognormal fit (median, beta) of per-record capacities by maximum likelihood, right-censored where NaN.

    Parameters
    ----------
    capacities : array_like, shape (n,)
        Capacity of each record [IM units], > 0; NaN where the record was not seen to fail.
    censor_at : float or array_like, shape (n,)
        Where a NaN capacity is censored [IM units]: the capacity lies above it (e.g. the highest
        intensity the record was seen to survive). Ignored for finite capacities.

    Returns
    -------
    (median, beta) : float
        Without censoring the closed form: median = exp(mean ln c), beta = the standard deviation of ln c
        with divisor n (the MLE). With censoring the maximum of the Tobit likelihood on ln c, which is
        concave in (mu/beta, 1/beta) (Olsen 1978): a quasi-Newton solve with the exact gradient to a
        relative parameter change of about 1e-10. (NaN, NaN) with fewer than two finite capacities or
        when every finite one is equal.
    """
    capacities = np.asarray(capacities, float)
    censor_at = np.broadcast_to(np.asarray(censor_at, float), capacities.shape)
    finite = np.isfinite(capacities)
    log_observed = np.log(capacities[finite])
    log_censored = np.log(censor_at[~finite])
    if log_observed.size < 2 or np.ptp(log_observed) == 0 or not np.all(np.isfinite(log_censored)):
        return np.nan, np.nan
    mean, std = log_observed.mean(), log_observed.std()
    if log_censored.size == 0:
        return float(np.exp(mean)), float(std)

    def negative(params):
        theta, h = params  # mu / beta and 1 / beta
        if h <= 0:
            return np.inf, np.zeros(2)
        residual = h * log_observed - theta  # (ln c - mu) / beta
        z = theta - h * log_censored  # P(capacity > c) = Phi((mu - ln c) / beta)
        log_tail = log_ndtr(z)
        ratio = np.exp(-0.5 * z**2 - 0.5 * np.log(2 * np.pi) - log_tail)  # phi(z) / Phi(z)
        value = np.sum(np.log(h) - 0.5 * residual**2) + np.sum(log_tail)
        d_theta = np.sum(residual) + np.sum(ratio)
        d_h = np.sum(1.0 / h - residual * log_observed) - np.sum(ratio * log_censored)
        return -value, -np.array([d_theta, d_h])

    start = np.array([mean / max(std, 0.05), 1.0 / max(std, 0.05)])
    result = minimize(negative, start, jac=True, method="BFGS", options={"gtol": 1e-10, "maxiter": 500})
    theta, h = result.x
    if not (result.success or np.linalg.norm(result.jac) < 1e-7) or h <= 0:
        result = minimize(lambda x: negative(x)[0], result.x, method="Nelder-Mead",
                          options={"xatol": 1e-12, "fatol": 1e-14, "maxiter": 20000})
        theta, h = result.x
    return float(np.exp(theta / h)), float(1.0 / h)


def goodness_of_fit(im, exceed, total, median, beta):
    """(deviance p-value, max |fitted - empirical|) of a fitted curve against the counts."""
    if not np.isfinite(median):
        return np.nan, np.nan
    keep = total > 0
    im, exceed, total = im[keep], exceed[keep], total[keep]
    dof = max(1, int(keep.sum()) - (1 if beta == 0 else 2))
    p = lognormal_cdf(im, median, beta)
    return float(chi2.sf(deviance(im, exceed, total, median, beta), dof)), float(np.max(np.abs(p - exceed / total)))


def curves_cross(im_grid, fits, tolerance=CROSSING_TOLERANCE):
    """True if any less severe state's curve falls below a more severe one on the grid by > tolerance."""
    curves = [lognormal_cdf(im_grid, m, b) for m, b in fits if np.isfinite(m)]
    return any(np.any(lower < upper - tolerance) for lower, upper in zip(curves, curves[1:]))
