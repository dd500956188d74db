"""rockfrag.report.words - the words a client reads: plain names for identifiers, glossary, references.

Input : identifiers as the result files write them (fit methods, row statuses, pivot-switch rules, bed
        laws, damage-state names, models that are not in the registry).
Output: plain words for each (``FIT_METHODS``, ``STATUS_WORDS``, ``SWITCH_WORDS``, ``BED_WORDS``,
        ``state_short_label``), the glossary page's entries (``glossary_items``) and the references page
        (``REFERENCES``, ``references_items``). ``CODE_IDENTIFIERS`` lists what must never reach a page
        (tests/test_report_words.py reads every page's text against it).
"""

from __future__ import annotations

import html
import re

from rockfrag.damage_states import TILT_WORDS, UPLIFT_WORDS
from rockfrag.models.ssi import PAPER_CITATION as _CITATION
from rockfrag.models.ssi import PAPER_TITLE  # noqa: F401 (the report's name for it)
from rockfrag.report.text import Item, bullet, heading, paragraph

PAPER_CITATION = re.sub(r" \([^()]*/[^()]*\)", "", _CITATION).replace("The copy the project holds",
                                                                     "The copy used")
"""The seed paper's citation as the client reads it: without the path of the project's copy (a file path is no
client's word; the appendix and cube.nc keep it)."""

FIT_METHODS = {
    "mle-binomial": "maximum likelihood on the counts per level",
    "mle-binomial-shared-beta": "maximum likelihood with one dispersion shared by the states (no crossing)",
    "exact-g-tan-alpha": "the exact uplift threshold g·tanα (a step)",
    "exact-thresholds": "a lognormal fit of each record's exact uplift intensity (g·tanα × its pair's RotD50 / its own "
                        "PGA), for the rigid base and the paper's model alike (its spring sits under the pivot, so "
                        "the block lifts off where the rigid block does: the same median on every soil)",
    "step-between-levels": "a step between two levels (every record changed state there)",
    "none": "no fit (the state was not reached, or reached by most records at the lowest level)",
}
"""``fit_method`` of fragility.nc in words."""

STATUS_WORDS = {
    "within": "fitted, median inside the studied range",
    "fitted": "fitted, median inside the studied range",
    "extrapolated": "median outside the studied range",
    "above-range": "reached only at the highest levels: median above the studied range",
    "below-range": "reached by most records at the lowest level: median below the studied range",
    "not-reached": "not reached at any level",
    "censored-at-cap": "median above the highest intensity studied: the records' fraction there instead",
    "deterministic-threshold": "an exact step at the uplift threshold",
    "separated": "a step between two levels",
    "no fit": "no fit",
}
"""A fitted row's ``status`` (fragility.csv) in words."""

SWITCH_WORDS = {
    "consistent": "at each impact the pivot switches with the rotation rate and the velocity of the centre of mass "
                  "unchanged, so the switch itself loses no energy; the spring's dashpot then takes out what the "
                  "corner impact would (a stiff spring gives Housner's restitution)",
    "continuous": "at each impact the pivot switches keeping the rotation rate and the vertical velocity",
}
"""The paper's model's pivot-switch rule in words."""

BED_WORDS = {
    "continuous": "springs and dashpots over the whole footprint",
    "two-spring": "two springs and dashpots, k/2 under each corner (k the whole bed's stiffness, as tabulated)",
    "hunt-crossley": "springs over the footprint with impact damping that vanishes with the penetration",
}
"""The tensionless bed's contact law in words."""

CODE_IDENTIFIERS = ("exact-g-tan-alpha", "mle-binomial", "pga_ratio", "pgv_ratio", "avgsa", "switch rule '",
                    "below-range", "above-range", "not-reached", "deterministic-threshold", "n_resurrected",
                    "capacity_median", "rocking-0.2", "rocking-0.5", "peak_friction_demand", "theta_max")
"""Strings no page of the report may show (tests also look for any snake_case word outside file names)."""


REFERENCES = {
    "paper": PAPER_CITATION + " The SSI-rocking model this study uses (a rigid block on one vertical "
             "spring-dashpot, derived from the Lagrangian; interface stiffness k of its eq. 19), its soils (Table "
             "1, representative values it states without a source) and its record (Duzce, Bolu). A preprint: "
             "Preprints.org posts papers before, and without, peer review.",
    "Housner 1963": "Housner, G. W. (1963). The behavior of inverted pendulum structures during earthquakes. "
                    "Bulletin of the Seismological Society of America 53(2), 403-417.",
    "ElGawady et al. 2011": "ElGawady, M. A., Ma, Q., Butterworth, J. W., Ingham, J. (2011). Effects of interface "
                            "material on the performance of free rocking blocks. Earthquake Engineering & "
                            "Structural Dynamics 40(4), 375-392.",
    "Boore 2010": "Boore, D. M. (2010). Orientation-independent, nongeometric-mean measures of seismic intensity "
                  "from two horizontal components of motion. Bulletin of the Seismological Society of America "
                  "100(4), 1830-1835, doi:10.1785/0120090400.",
    "Boore et al. 2014": "Boore, D. M., Stewart, J. P., Seyhan, E., Atkinson, G. M. (2014). NGA-West2 equations "
                         "for predicting PGA, PGV, and 5% damped PSA for shallow crustal earthquakes. Earthquake "
                         "Spectra 30(3), 1057-1085 (the site term that carries the reference hazard to each soil).",
    "Seyhan & Stewart 2014": "Seyhan, E., Stewart, J. P. (2014). Semi-empirical nonlinear site amplification from "
                             "NGA-West2 data and simulations. Earthquake Spectra 30(3), 1241-1256.",
    "Bazzurro & Cornell 2004": "Bazzurro, P., Cornell, C. A. (2004). Nonlinear soil-site effects in probabilistic "
                               "seismic-hazard analysis. Bulletin of the Seismological Society of America 94(6), "
                               "2110-2123.",
    "Baker 2015": "Baker, J. W. (2015). Efficient analytical fragility function fitting using dynamic structural "
                  "analysis. Earthquake Spectra 31(1), 579-599.",
    "Vamvatsikos & Cornell 2002": "Vamvatsikos, D., Cornell, C. A. (2002). Incremental dynamic analysis. "
                                  "Earthquake Engineering & Structural Dynamics 31(3), 491-514.",
    "Cornell et al. 2002": "Cornell, C. A., Jalayer, F., Hamburger, R. O., Foutch, D. A. (2002). Probabilistic basis "
                           "for 2000 SAC Federal Emergency Management Agency steel moment frame guidelines. "
                           "Journal of Structural Engineering 128(4), 526-533.",
    "FEMA P695": "FEMA (2009). Quantification of Building Seismic Performance Factors, FEMA P695. Federal "
                 "Emergency Management Agency, Washington DC (its far-field and near-field record sets; the methods "
                 "name the one this study runs).",
    "FEMA P-58": "FEMA (2018). Seismic Performance Assessment of Buildings, FEMA P-58, 2nd ed. Federal Emergency "
                 "Management Agency, Washington DC (fragility functions, combined dispersion of record-to-record "
                 "and model uncertainty).",
    "ASCE 7-22": "ASCE (2022). Minimum Design Loads and Associated Criteria for Buildings and Other Structures, "
                 "ASCE/SEI 7-22 (risk-targeted ground motions: 1% probability of collapse in 50 years).",
    "ASCE 7-16": "ASCE (2017). Minimum Design Loads and Associated Criteria for Buildings and Other Structures, "
                 "ASCE/SEI 7-16 (Table 20.3-1: site classes by Vs30).",
    "EN 1998": "CEN (2004). Eurocode 8: Design of structures for earthquake resistance, Part 1: General rules, "
               "seismic actions and rules for buildings, EN 1998-1:2004 (Table 3.1: ground types, by Vs30 A > 800, "
               "B 360-800, C 180-360, D < 180 m/s; E, S1 and S2 by the profile).",
    "ASCE 4-16": "ASCE (2017). Seismic Analysis of Safety-Related Nuclear Structures, ASCE/SEI 4-16 (the range of "
                 "soil stiffness to analyse, G(1 + C_v) to G/(1 + C_v)).",
    "USGS hazard tools": "U.S. Geological Survey, National Seismic Hazard Model project: the nshmp-haz code and the "
                         "Unified Hazard Tool (the Vs30 that stands for each site class).",
    "IEEE 693": "IEEE (2018). IEEE Recommended Practice for Seismic Design of Substations, IEEE Std 693-2018.",
    "Psycharis & Jennings 1983": "Psycharis, I. N., Jennings, P. C. (1983). Rocking of slender rigid bodies allowed "
                                 "to uplift. Earthquake Engineering & Structural Dynamics 11(1), 57-76.",
    "Chopra & Yim 1985": "Chopra, A. K., Yim, S. C.-S. (1985). Simplified earthquake analysis of structures with "
                         "foundation uplift. Journal of Structural Engineering 111(4), 906-930.",
    "Acikgoz & DeJong 2012": "Acikgoz, S., DeJong, M. J. (2012). The interaction of elasticity and rocking in "
                             "flexible structures allowed to uplift. Earthquake Engineering & Structural Dynamics "
                             "41(15), 2177-2194.",
    "Gazetas 1991": "Gazetas, G. (1991). Formulas and charts for impedances of surface and embedded foundations. "
                    "Journal of Geotechnical Engineering 117(9), 1363-1381.",
    "Shenton 1996": "Shenton, H. W. (1996). Criteria for initiation of slide, rock, and slide-rock rigid-body modes. "
                    "Journal of Engineering Mechanics 122(7), 690-693.",
    "Luco & Cornell 2007": "Luco, N., Cornell, C. A. (2007). Structure-specific scalar intensity measures for "
                           "near-source and ordinary earthquake ground motions. Earthquake Spectra 23(2), 357-392 "
                           "(efficiency and sufficiency of intensity measures).",
    "Kalliontzis et al. 2016": "Kalliontzis, D., Sritharan, S., Schultz, A. E. (2016). Improved coefficient of "
                               "restitution estimation for free rocking members. Journal of Structural Engineering "
                               "142(12), 06016002.",
    "Ther & Kollár 2017": "Ther, T., Kollár, L. P. (2017). Refinement of Housner's model on rocking blocks. "
                          "Bulletin of Earthquake Engineering 15(5), 2305-2319.",
    "NAVFAC DM-7.02": "NAVFAC (1986). Foundations and Earth Structures, Design Manual 7.02. Naval Facilities "
                      "Engineering Command, Alexandria VA (Table 1: ultimate friction factors and adhesion for "
                      "dissimilar materials).",
    "Prandtl 1921": "Prandtl, L. (1921). Über die Eindringungsfestigkeit (Härte) plastischer Baustoffe und die "
                    "Festigkeit von Schneiden. Zeitschrift für angewandte Mathematik und Mechanik 1(1), 15-20 "
                    "(N_c = 2 + π of a strip on undrained clay).",
    "Vesic 1973": "Vesic, A. S. (1973). Analysis of ultimate loads of shallow foundations. Journal of the Soil "
                  "Mechanics and Foundations Division 99(SM1), 45-73 (N_γ = 2(N_q + 1) tan φ).",
    "Terzaghi & Peck 1967": "Terzaghi, K., Peck, R. B. (1967). Soil Mechanics in Engineering Practice, 2nd ed. "
                            "Wiley, New York (consistency of clay by unconfined compressive strength).",
    "Luco & Bazzurro 2007": "Luco, N., Bazzurro, P. (2007). Does amplitude scaling of ground motion records result "
                            "in biased nonlinear structural drift responses? Earthquake Engineering & Structural "
                            "Dynamics 36(13), 1813-1835.",
    "Gajan & Kutter 2008": "Gajan, S., Kutter, B. L. (2008). Capacity, settlement, and energy dissipation of shallow "
                           "footings subjected to rocking. Journal of Geotechnical and Geoenvironmental Engineering "
                           "134(8), 1129-1141.",
    "AISC 360-16": "AISC (2016). Specification for Structural Steel Buildings, ANSI/AISC 360-16. American Institute "
                   "of Steel Construction, Chicago (J3.8: slip coefficient of faying surfaces).",
    "Makris & Vassiliou 2012": "Makris, N., Vassiliou, M. F. (2012). Sizing the slenderness of free-standing rocking "
                               "columns to withstand earthquake shaking. Archive of Applied Mechanics 82, 1497-1511.",
}
"""The works the report cites, by the short name the pages use."""


def listed(words) -> str:
    """"a", "a and b", "a, b and c": names in running text."""
    words = list(words)
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]


def references_items(cited: str | None = None) -> list[Item]:
    """The references page: the seed paper first, then the others in the order of the dict.

    With ``cited`` (the text of the report's other pages), only the works it cites: a study without a steel base
    does not cite the steel slip coefficient's source, nor one with a curve per soil the site term's.
    """
    cited = html.unescape(cited) if cited is not None else None  # the pages' HTML: "Seyhan &amp; Stewart 2014"
    items = [paragraph("The pages cite these works by the short name before each entry.")]
    items += [bullet(f"{'The paper' if key == 'paper' else key}: {text}") for key, text in REFERENCES.items()
              if cited is None or key == "paper" or key in cited]
    return items


GLOSSARY = (
    ("θmax/α", "the largest rocking angle of a run over the block's slenderness angle α; 1 is the tipping point "
               "of a block at rest; on the IDA pages a run that overturns is drawn at θmax/α = 1.6, the right "
               "edge of each panel."),
    ("α, R", "slenderness angle (tan α = half-width over half-height) and the half-diagonal of the block; of two "
             "blocks with the same α the larger (larger R) is the more stable (Makris & Vassiliou 2012)."),
    ("uplift threshold", "the ground acceleration at which the block starts to rock on a rigid base: g·tanα."),
    ("uplift (lift-off)", f"{UPLIFT_WORDS}; the first damage state. A smaller lift is not uplift: see 'tilts on "
                          "the bed'."),
    (TILT_WORDS, "a base corner parts from a compliant bed by less than the uplift size: the bed gives under the "
                 "toe and the block leans, but it does not rock about its edge."),
    ("tied base", "a base held against sliding in a model's runs (no friction limit), so the block can only rock; "
                  "the limitations' 'Sliding' says which runs tie it."),
    ("rocks", "the block pivots about a bottom edge with a base corner lifted at least the uplift size."),
    ("at rest, slides, slides and rocks, overturns", "the other words of the answer pages' motion tables: no "
     "corner lifts and the base does not slip (at rest); the base slips on the ground without rocking (slides); it "
     "slips and rocks in the same record (slides and rocks); the rocking angle reaches the overturning angle "
     "(overturns). Each record is counted once, under the most severe motion it made."),
    ("marks *, †, ‡, §, ≥, <", "the marks of the tables, each explained under its table and in 'Reading the "
     "answer pages': * the fitted curve carried outside the intensities run: a median outside them, or a "
     "probability read at a site intensity below the lowest level run (where the records' table shows '-'); "
     "† a median above the largest intensity any record reached unscaled "
     "(extrapolation by scaling); ‡ a fitted curve that fails its goodness-of-fit test; § a value driven by the "
     "base friction; '≥ X', '< X' a bound where the records give no fitted value."),
    ("anchor (verdict)", "the block must not stand free; the report does not size the anchorage, which is designed "
                         "as a nonstructural component fixed to its support (ASCE 7-22 Chapter 13) or to the "
                         "equipment's own qualification standard (IEEE 693 for substation equipment)."),
    ("damage state", "an outcome the fragility gives the probability of: uplift, a base slip of at least a stated "
                     "distance (0.05 m, 0.30 m), θmax/α above a limit, overturning."),
    ("fragility curve", "P(damage state | intensity), a lognormal distribution: median (the intensity at which "
                        "half the records reach the state) and dispersion β."),
    ("β (dispersion)", "the standard deviation of the logarithm of the intensity at which the state is reached; "
                       "from record to record, plus the model's own uncertainty where the recommended curve "
                       "adds it."),
    ("confidence bounds", "the bounds of a fitted curve's median from fitting it again with the records "
                          "resampled (bootstrap); drawn as shading around the curve."),
    ("sensitivity runs", "the runs of the recommended model with one uncertain parameter (restitution, friction, "
                        "bed stiffness) at the low or high end of its range, the others central; the spread of "
                        "their medians is the parameters' part of the model dispersion."),
    ("IM (intensity measure)", "the number that says how strong the shaking is: PGA (peak ground acceleration), "
                               "PGV (peak ground velocity), Sa (spectral acceleration), Ia (Arias intensity, "
                               "π/(2g) times the integral of the squared acceleration, in m/s), D5-95 (the time "
                               "between 5% and 95% of Ia)."),
    ("G_s, E_d, ξ, k", "the soil's shear modulus, its constrained (oedometric) modulus, the damping ratio of the "
                       "foundation's dashpot, and the foundation's vertical stiffness under the block (the "
                       "paper's eq. 19)."),
    ("μ_s (base friction)", "the static friction coefficient between the block's base and the ground: below the "
                            "block's width over height the block slides before it can rock (Shenton 1996)."),
    ("IDA (incremental dynamic analysis)", "each record is scaled to a ladder of intensities and run at each "
                                           "(Vamvatsikos & Cornell 2002)."),
    ("extrapolation by scaling", "an intensity above the largest any record of the set reached unscaled: there the "
                                 "results come from records multiplied by large factors, not from ground motions "
                                 "that occurred."),
    ("return period", "the mean time between exceedances of an intensity at the site: 475, 975 and 2,475 years "
                      "are 10%, 5% and 2% probability in 50 years."),
    ("annual frequency, probability in the design life", "how often per year the state is reached, integrated over "
                                                         "the site's hazard curve, and the chance that it happens at "
                                                         "least once in the design life."),
    ("restitution", "the share of rocking speed a block keeps at each impact; Housner's rigid base gives "
                    "r = 1 − 1.5 sin²α, and experiments on rigid bases find about that value or a few percent more "
                    "(ElGawady et al. 2011; Kalliontzis et al. 2016; Ther & Kollár 2017)."),
    ("record sets", "the sets of earthquake records available to a study: FEMA P695's far-field set, and its "
                    "near-field set (records with and without a velocity pulse); the methods name the set this "
                    "study runs."),
    ("flies, free flight", "the whole base leaves the ground, a corner at least the uplift size: after an "
                           "impact on a bed (the block bounces), or in free flight, where the ground drops faster "
                           "than gravity (g + a_v < 0 under the vertical component, only where a study applies "
                           "it); the pivot "
                           "models stop at free flight, the Winkler bed follows the block through the air until it "
                           "lands."),
    ("pulse period, pulse acceleration", "of a record's dominant velocity pulse, taken as one full sine cycle: "
                                         "its period T_p and its acceleration amplitude a_p = 2π·PGV/T_p; the "
                                         "efficiency page tests whether the capacity still "
                                         "depends on T_p."),
    ("friction demand", "the base friction coefficient a run needs to rock without sliding; above the assumed one "
                        "the block would slide."),
    ("Housner model", "a rigid block rocking on a rigid base (Housner 1963): the reference; it does not depend on "
                      "the soil."),
    ("SSI-rocking model (the paper's)", "a rigid block on one vertical spring and dashpot under the active corner "
                                        "(the paper); its spring can pull on the block, which a soil cannot."),
    ("tensionless Winkler bed", "a rigid block on a bed of springs and dashpots that push but never pull: the block "
                                "lifts off instead (Psycharis & Jennings 1983; Chopra & Yim 1985)."),
    ("recommended curve", "the tensionless bed with the soil's stated friction and stiffness and the centre of the "
                          "experimental restitution range; its β adds the model's uncertainty (FEMA P695's "
                          "model-quality rating, the counterpart of FEMA P-58's modelling dispersion β_q, or the "
                          "sensitivity runs' spread where larger) to the record-to-record part."),
    ("highest intensity studied", "the highest intensity the study runs (its value and reason are in the "
                                  "methods: 3 g PGA lies above the largest horizontal PGA in the strong-motion "
                                  "databases); no "
                                  "level, fit or median lies above it, and a probability adds the site's chance "
                                  "of exceeding it as an upper bound."),
    ("RotD50", "the median over all horizontal orientations of a station's two components (Boore 2010), the "
               "intensity hazard models give; each pair of components is scaled together by it."),
)
"""The glossary page: term, one line."""


def glossary_items() -> list[Item]:
    """The glossary page's entries, one bullet each."""
    return [heading("Terms"), *[bullet(f"{term}: {text}") for term, text in GLOSSARY]]


def state_short_label(name: str, description: str) -> str:
    """A damage state in a table header: its description when short ("θmax/α ≥ 0.5"), else its name in words.

    A slip state says its threshold with its unit ("slip ≥ 0.05 m"): its name alone ("slip 0.05") gives no unit.
    """
    from rockfrag.damage_states import DAMAGE_STATES, is_slip_state

    state = DAMAGE_STATES.get(name)
    if state is not None and is_slip_state(state):
        return f"slip ≥ {state.threshold:.2f} m"  # the slip EDP is in metres (rockfrag.damage_states)
    text = description.replace("theta_max", "θmax").replace("alpha", "α").replace(">=", "≥")
    if text and len(text) <= 16:
        return text
    return name.replace("-", " ").replace("_", " ")


FORMULAS = ((re.compile(r"sin\^2\s*\(?\s*(?:alpha|α)\s*\)?"), "sin²α"),
            (re.compile(r"(?<=[A-Za-z])\^2(?![0-9])"), "²"), (re.compile(r"(?<=[A-Za-z])\^3(?![0-9])"), "³"))
"""A formula as a registry or model description writes it in ASCII, and as the report prints it (one spelling)."""


def formulas(text: str) -> str:
    """ASCII formulas and units of ``text`` as the report spells them: "sin^2(alpha)" -> "sin²α", "m^3" -> "m³"."""
    for pattern, spelled in FORMULAS:
        text = pattern.sub(spelled, text)
    return text


def plain(text: str) -> str:
    """A status, fit method or rule as words (the input when it has none)."""
    for table in (STATUS_WORDS, FIT_METHODS, SWITCH_WORDS, BED_WORDS):
        if text in table:
            return table[text]
    return text
