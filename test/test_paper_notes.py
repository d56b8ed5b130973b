"""docs/paper_notes.md: every number it states, recomputed with the package's functions.

Each table row ``| `check id` | value |`` of the document must be a check this file
knows, and each check must appear in the document; the value computed here must
equal the printed one to the precision printed. The paper's formulas "as printed"
are written out below, independently of the package. The ``name = value``
parameters in the last column of sections 4 and 5's tables must be PlannerConfig's
defaults.
"""

from decimal import Decimal
import math
import re

from conftest import REPO
import numpy as np
import pytest

from subapf_planner.core.config import PlannerConfig
from subapf_planner.core.potentials import (
    max_subharmonic_slope,
    repulsive_dr,
    repulsive_field,
    repulsive_laplacian,
    repulsive_value,
)

pytestmark = pytest.mark.core

DOC = REPO / 'docs' / 'paper_notes.md'
FOUR = np.array([[1.0, 1.0], [-1.0, -1.0], [-1.0, 1.0], [1.0, -1.0]])
LN10 = math.log(10.0)

# The paper's potentials as printed (one obstacle point at the origin, or the four).
PRINTED = {
    'eq6': lambda r: np.log10(r),
    'eq8': lambda r: -1.0 / r,
    'eq13': lambda r, a=1.0, k=4.0: -a * np.exp(-k * r * r),
}


def eq10_printed(q):
    return float(-sum(1.0 / np.hypot(*(np.asarray(q, float) - p)) for p in FOUR))


def hessian(f, p, h=1e-4):
    p = np.asarray(p, float)
    out = np.zeros((2, 2))
    for i, ei in enumerate(np.eye(2) * h):
        for j, ej in enumerate(np.eye(2) * h):
            out[i, j] = (f(p + ei + ej) - f(p + ei - ej) - f(p - ei + ej)
                         + f(p - ei - ej)) / (4 * h * h)
    return out


def radial(f, r, h=1e-6):
    """d f / d r by central differences."""
    return (f(r + h) - f(r - h)) / (2 * h)


def away(kind, r, a=1.0, k=4.0):
    """Force component away from an obstacle at the origin, robot at (r, 0): from the
    package's field gradient, checked against finite differences of its value."""
    _, grad = repulsive_field(kind, [r, 0.0], [[0.0, 0.0]], a, k)
    numeric = radial(lambda x: float(repulsive_value(kind, x, a, k)), r)
    assert -grad[0, 0] == pytest.approx(-numeric, rel=1e-6)
    return float(-grad[0, 0])


def laplacian(kind, r, a=1.0, k=4.0):
    """The package's analytic Laplacian, checked against the Hessian's trace."""
    value = float(repulsive_laplacian(kind, r, a, k))
    f = (lambda q: float(repulsive_value(kind, np.hypot(*q), a, k)))
    assert np.trace(hessian(f, [r, 0.0], h=1e-3 * r)) == pytest.approx(value, abs=1e-3)
    return value


def four(kind, a=1.0, k=4.0):
    return lambda q: float(repulsive_field(kind, q, FOUR, a, k)[0][0])


def four_eigenvalue(f):
    """The (equal) Hessian eigenvalues at the origin, where the gradient vanishes."""
    grad = [(f(e) - f(-e)) / 2e-6 for e in np.eye(2) * 1e-6]
    np.testing.assert_allclose(grad, 0.0, atol=1e-6)
    eig = np.linalg.eigvalsh(hessian(f, [0.0, 0.0]))
    assert eig[0] == pytest.approx(eig[1], abs=1e-6)
    return float(eig.mean())


def ring_drop(f, radius):
    ring = [f([radius * math.cos(t), radius * math.sin(t)])
            for t in np.linspace(0.0, 2 * math.pi, 721)]
    return min(ring) - f([0.0, 0.0])


def slope_peak(a, k):
    """(max |dphi/dr|, where) of a exp(-k r^2), found on a fine grid and checked against
    max_subharmonic_slope."""
    r = np.linspace(1e-4, 3.0, 300_001)
    s = np.abs(repulsive_dr('subharmonic', r, a, k))
    i = int(np.argmax(s))
    assert s[i] == pytest.approx(max_subharmonic_slope(a, k), rel=1e-9)
    return float(s[i]), float(r[i])


def printed_laplacian_eq13(r, a, k):
    f = (lambda q: float(PRINTED['eq13'](np.hypot(*q), a, k)))
    return float(np.trace(hessian(f, [r, 0.0], h=1e-3 * r)))


def true_log10_slope(r):
    return radial(lambda x: math.log10(x), r)


CHECKS = {
    # section 1
    'away(traditional, a=1, r=0.5)': lambda: away('traditional', 0.5),
    'away(harmonic, a=1, r=0.5)': lambda: away('harmonic', 0.5),
    'away(subharmonic, a=1, k=4, r=0.5)': lambda: away('subharmonic', 0.5),
    'away_printed(eq8, r=0.5)': lambda: -radial(PRINTED['eq8'], 0.5),
    'away_printed(eq6, r=0.5)': lambda: -radial(PRINTED['eq6'], 0.5),
    'away_printed(eq13, a=1, k=4, r=0.5)': lambda: -radial(PRINTED['eq13'], 0.5),
    'dphi_dr(harmonic, a=1, r=1)': lambda: float(repulsive_dr('harmonic', 1.0, 1.0, 4.0)),
    'eq11_printed(r=1)': lambda: LN10 / 1.0,
    'eq11_printed(r=1) / true slope': lambda: (LN10 / 1.0) / true_log10_slope(1.0),
    'laplacian_printed(eq13, a=1, k=4, r=0.6)': lambda: printed_laplacian_eq13(0.6, 1.0, 4.0),
    # section 2
    'laplacian(subharmonic, a=1, k=4, r=0.2)': lambda: laplacian('subharmonic', 0.2),
    'laplacian(subharmonic, a=1, k=4, r=0.5)': lambda: laplacian('subharmonic', 0.5),
    'laplacian(subharmonic, a=1, k=4, r=0.6)': lambda: laplacian('subharmonic', 0.6),
    'laplacian(subharmonic, a=1, k=4, r=1.0)': lambda: laplacian('subharmonic', 1.0),
    'd0(k=4)': lambda: 1.0 / math.sqrt(4.0),
    'k(PlannerConfig())': lambda: PlannerConfig().k,
    # section 3
    'hessian_eigenvalues_four(traditional, a=1)': lambda: four_eigenvalue(four('traditional')),
    'hessian_eigenvalues_four(harmonic, a=1)': lambda: four_eigenvalue(four('harmonic')),
    'hessian_eigenvalues_four(subharmonic, a=1, k=4)':
        lambda: four_eigenvalue(four('subharmonic')),
    'hessian_eigenvalues_four_printed(eq10)': lambda: four_eigenvalue(eq10_printed),
    'laplacian_four(subharmonic, a=1, k=4)':
        lambda: float(np.trace(hessian(four('subharmonic'), [0.0, 0.0]))),
    'ring_drop_four(harmonic, a=1, radius=0.3)': lambda: ring_drop(four('harmonic'), 0.3),
    'ring_drop_four(subharmonic, a=1, k=4, radius=0.1)':
        lambda: ring_drop(four('subharmonic'), 0.1),
    'max_slope(subharmonic, a=1, k=4)': lambda: slope_peak(1.0, 4.0)[0],
    'argmax_slope(subharmonic, a=1, k=4)': lambda: slope_peak(1.0, 4.0)[1],
    'max_slope(subharmonic, a=0.5, k=16)': lambda: slope_peak(0.5, 16.0)[0],
    'argmax_slope(subharmonic, a=0.5, k=16)': lambda: slope_peak(0.5, 16.0)[1],
    'slope(traditional, a=0.5, r=0.05)':
        lambda: abs(float(repulsive_dr('traditional', 0.05, 0.5, 16.0))),
    'slope(harmonic, a=0.5, r=0.05)':
        lambda: abs(float(repulsive_dr('harmonic', 0.05, 0.5, 16.0))),
}


def sections() -> dict[int, str]:
    text = DOC.read_text()
    parts = re.split(r'^## (\d+)\. ', text, flags=re.M)
    return {int(n): body for n, body in zip(parts[1::2], parts[2::2], strict=True)}


def doc_values() -> dict[str, str]:
    rows = re.findall(r'^\| `([^`]+)` \| ([^|]+?) \|$', DOC.read_text(), flags=re.M)
    found: dict[str, str] = {}
    for check, value in rows:
        assert check not in found, f'{check} twice in {DOC.name}'
        found[check] = value.strip()
    return found


def test_the_four_sections_docstrings_point_to_are_there():
    text = DOC.read_text()
    for n, title in ((1, 'Signs'), (2, 'Where the exponential is subharmonic'),
                     (3, '"Subharmonic functions have no local minimum" is false'),
                     (4, 'Decisions the paper leaves open'),
                     (5, 'Beyond the paper: a navigation function')):
        assert re.search(rf'^## {n}\. {re.escape(title)}', text, flags=re.M), n


def test_every_number_in_the_doc_is_a_known_check_and_vice_versa():
    assert set(doc_values()) == set(CHECKS)


@pytest.mark.parametrize('check', sorted(CHECKS))
def test_number_in_the_doc_is_what_the_code_computes(check):
    printed = doc_values()[check]
    half_unit = 0.5 * 10.0 ** Decimal(printed).as_tuple().exponent
    computed = CHECKS[check]()
    assert abs(computed - float(printed)) <= half_unit * (1 + 1e-9), (check, computed)
    if float(printed) != 0.0:    # a printed sign means something: keep it right
        assert math.copysign(1.0, computed) == math.copysign(1.0, float(printed)), check


def test_sign_change_of_the_exponential_laplacian_is_at_d0():
    """Section 2: negative inside d0, positive outside, for more than the four radii."""
    for k in (4.0, 16.0, 25.0):
        d0 = 1.0 / math.sqrt(k)
        inside = np.linspace(0.05 * d0, 0.98 * d0, 20)
        outside = np.linspace(1.02 * d0, 4.0 * d0, 20)
        assert np.all(repulsive_laplacian('subharmonic', inside, 1.0, k) < 0)
        assert np.all(repulsive_laplacian('subharmonic', outside, 1.0, k) > 0)


@pytest.mark.parametrize('section, at_least', [(4, 15), (5, 2)])
def test_parameters_in_the_tables_are_the_defaults(section, at_least):
    rows = [line.split('|')[-2] for line in sections()[section].splitlines()
            if line.startswith('| ') and not line.startswith('| question')]
    params = [p for cell in rows for p in re.findall(r'`(\w+) = ([^`]+)`', cell)]
    assert len(params) >= at_least
    cfg = PlannerConfig()
    for name, value in params:
        default = getattr(cfg, name)
        if isinstance(default, str):
            assert value == default, name
        else:
            assert float(value) == pytest.approx(default), name
