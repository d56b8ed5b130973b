"""Potentials: analytic derivatives, Laplacian signs, the four-point example
(docs/paper_notes.md sections 1-3)."""

import math

from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

from subapf_planner.core.potentials import (
    attractive_gradient,
    attractive_value,
    max_subharmonic_slope,
    repulsive_dr,
    repulsive_field,
    repulsive_gradient,
    repulsive_laplacian,
    repulsive_value,
)

pytestmark = pytest.mark.core

KINDS = ('traditional', 'harmonic', 'subharmonic')
FOUR = np.array([[1.0, 1.0], [-1.0, -1.0], [-1.0, 1.0], [1.0, -1.0]])


def numeric_gradient(f, p, h=1e-6):
    p = np.asarray(p, float)
    return np.array([(f(p + e) - f(p - e)) / (2 * h) for e in np.eye(2) * h])


def hessian(f, p, h=1e-4):
    p = np.asarray(p, float)
    out = np.zeros((2, 2))
    for i, ei in enumerate(np.eye(2) * h):
        for j, ej in enumerate(np.eye(2) * h):
            out[i, j] = (f(p + ei + ej) - f(p + ei - ej) - f(p - ei + ej)
                         + f(p - ei - ej)) / (4 * h * h)
    return out


@pytest.mark.parametrize('kind', KINDS)
@given(r=st.floats(0.05, 3.0))
@settings(max_examples=60, deadline=None)
def test_radial_derivative_matches_finite_difference(kind, r):
    h = 1e-6 * max(r, 1.0)
    numeric = (repulsive_value(kind, r + h, 0.7, 16.0)
               - repulsive_value(kind, r - h, 0.7, 16.0)) / (2 * h)
    assert repulsive_dr(kind, r, 0.7, 16.0) == pytest.approx(numeric, rel=1e-5, abs=1e-7)


@pytest.mark.parametrize('kind', KINDS)
@pytest.mark.parametrize('nearest', [False, True])
def test_field_gradient_matches_finite_difference(kind, nearest):
    rng = np.random.default_rng(1)
    obs = rng.uniform(-2, 2, (7, 2))
    for p in rng.uniform(-2, 2, (20, 2)):
        if np.min(np.hypot(*(obs - p).T)) < 0.1:
            continue
        value = (lambda q: repulsive_field(kind, q, obs, 0.5, 9.0, nearest_only=nearest)[0][0])
        _, grad = repulsive_field(kind, p, obs, 0.5, 9.0, nearest_only=nearest)
        np.testing.assert_allclose(grad[0], numeric_gradient(value, p), rtol=1e-4, atol=1e-6)


@pytest.mark.parametrize('kind', KINDS)
@given(points=st.lists(st.tuples(st.floats(-3, 3), st.floats(-3, 3)), min_size=1, max_size=5),
       obstacles=st.lists(st.tuples(st.floats(-3, 3), st.floats(-3, 3)), max_size=6),
       nearest=st.booleans(), influence=st.sampled_from([0.5, 1.5, math.inf]))
@settings(max_examples=60, deadline=None)
def test_gradient_alone_is_the_fields_gradient(kind, points, obstacles, nearest, influence):
    """repulsive_gradient (the APF step's) gives repulsive_field's gradient, bit for bit,
    obstacle points on a point and no obstacles included."""
    pts = np.asarray(points, float)
    obs = np.asarray(obstacles, float).reshape(-1, 2)
    if len(obs):
        obs[0] = pts[0]   # one at distance zero
    before = (pts.copy(), obs.copy())
    grad = repulsive_gradient(kind, pts, obs, 0.5, 9.0, nearest_only=nearest,
                              influence=influence)
    _, expected = repulsive_field(kind, pts, obs, 0.5, 9.0, nearest_only=nearest,
                                  influence=influence)
    assert grad.shape == (len(pts), 2)
    np.testing.assert_array_equal(grad, expected)
    np.testing.assert_array_equal(pts, before[0])
    np.testing.assert_array_equal(obs, before[1])


@pytest.mark.parametrize('kind', ['quadratic', 'conic'])
def test_attractive_gradient_matches_finite_difference(kind):
    goal = np.array([0.3, -1.2])
    for p in np.random.default_rng(2).uniform(-3, 3, (20, 2)):
        g = attractive_gradient(kind, p, goal, 1.3)
        np.testing.assert_allclose(
            g, numeric_gradient(lambda q: attractive_value(kind, q, goal, 1.3), p),
            rtol=1e-5, atol=1e-7)


@pytest.mark.parametrize('kind', KINDS)
@given(r=st.floats(0.1, 2.0))
@settings(max_examples=40, deadline=None)
def test_laplacian_matches_numeric(kind, r):
    f = (lambda q: float(repulsive_value(kind, np.hypot(*q), 1.0, 4.0)))
    lap = np.trace(hessian(f, [r, 0.0], h=1e-3 * r))
    # finite-difference error of the second derivative grows like 1/r^2
    assert repulsive_laplacian(kind, r, 1.0, 4.0) == pytest.approx(lap, rel=1e-3,
                                                                   abs=1e-4 / r ** 2)


def test_exponential_laplacian_sign_on_both_sides_of_d0():
    """docs/paper_notes.md section 2: lap(a exp(-k r^2)) < 0 inside d0 = 1/sqrt(k),
    >= 0 outside."""
    a, k = 1.0, 4.0
    d0 = 1 / math.sqrt(k)
    f = (lambda q: float(repulsive_value('subharmonic', np.hypot(*q), a, k)))
    expected = {0.2: -11.45, 0.6: 1.668, 1.0: 0.879}
    for r, value in expected.items():
        lap = np.trace(hessian(f, [r, 0.0]))
        assert lap == pytest.approx(value, abs=0.01)
    for r in np.linspace(0.05, d0 - 0.01, 10):
        assert np.trace(hessian(f, [r, 0.0])) < 0
    for r in np.linspace(d0 + 0.01, 2.0, 10):
        assert np.trace(hessian(f, [0.0, r])) > 0


def _four(kind, k=4.0):
    return lambda q: float(repulsive_field(kind, q, FOUR, 1.0, k)[0][0])


def test_four_points_traditional_has_strict_minimum_at_centre():
    f = _four('traditional')
    np.testing.assert_allclose(numeric_gradient(f, [0, 0]), 0, atol=1e-6)
    eig = np.linalg.eigvalsh(hessian(f, [0, 0]))
    np.testing.assert_allclose(eig, [0.707, 0.707], atol=0.002)


def test_four_points_harmonic_has_no_minimum_at_centre():
    f = _four('harmonic')
    eig = np.linalg.eigvalsh(hessian(f, [0, 0]))
    assert abs(eig.sum()) < 1e-4          # harmonic: trace of the Hessian is 0
    np.testing.assert_allclose(eig, 0, atol=1e-3)   # degenerate saddle
    # some direction descends from the centre at third/fourth order
    ring = [f([0.3 * math.cos(a), 0.3 * math.sin(a)]) for a in np.linspace(0, 2 * np.pi, 64)]
    assert min(ring) < f([0, 0])


def test_four_points_exponential_also_has_a_local_minimum():
    """docs/paper_notes.md section 3: 'subharmonic means no local minimum' is false:
    there is one at 0."""
    f = _four('subharmonic', k=4.0)
    eig = np.linalg.eigvalsh(hessian(f, [0, 0]))
    np.testing.assert_allclose(eig, [0.075, 0.075], atol=0.002)
    ring = [f([0.1 * math.cos(a), 0.1 * math.sin(a)]) for a in np.linspace(0, 2 * np.pi, 64)]
    assert min(ring) > f([0, 0])


@given(a=st.floats(0.1, 5.0), k=st.floats(1.0, 100.0))
@settings(max_examples=50, deadline=None)
def test_exponential_slope_is_bounded_unlike_inverse_and_log(a, k):
    r = np.geomspace(1e-5, 5.0, 4000)
    slope = np.abs(repulsive_dr('subharmonic', r, a, k))
    bound = max_subharmonic_slope(a, k)
    assert slope.max() <= bound * (1 + 1e-9)
    assert slope.max() == pytest.approx(bound, rel=1e-3)
    assert np.abs(repulsive_dr('traditional', 1e-4, a, k)) > 1e3 * bound
    assert np.abs(repulsive_dr('harmonic', 1e-5, a, k)) > 10 * bound


def test_repulsion_pushes_away_from_obstacle():
    for kind in KINDS:
        _, grad = repulsive_field(kind, [1.0, 0.0], [[0.0, 0.0]], 1.0, 4.0)
        assert grad[0, 0] < 0 and abs(grad[0, 1]) < 1e-12  # -grad points to +x


def test_inputs_not_mutated_and_empty_obstacles():
    p = np.array([[0.2, 0.3]])
    obs = np.array([[1.0, 1.0]])
    p0, obs0 = p.copy(), obs.copy()
    repulsive_field('subharmonic', p, obs, 1.0, 4.0)
    np.testing.assert_array_equal(p, p0)
    np.testing.assert_array_equal(obs, obs0)
    v, g = repulsive_field('traditional', p, np.zeros((0, 2)), 1.0, 4.0)
    assert v.tolist() == [0.0] and g.tolist() == [[0.0, 0.0]]
