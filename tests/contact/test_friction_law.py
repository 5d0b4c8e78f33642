"""Coulomb's return mapping on its own: the cone, the two branches, their
derivatives, and the checks of μ and ε_T."""
from __future__ import annotations

import numpy as np
import pytest

from dolfinx_mortar.contact.laws import SLIP, STICK, SEPARATED, CoulombFriction

RNG = np.random.default_rng(7)


def mapping_at(trial, normal_force=1.0, mu=0.4, weight=3.0, active=True):
    law = CoulombFriction(mu)
    trial = np.atleast_2d(np.asarray(trial, dtype=float))
    n = len(trial)
    return law.return_mapping(trial, np.full(n, normal_force), np.full(n, weight),
                              np.full(n, active))


@pytest.mark.parametrize("gdim", [2, 3])
def test_inside_the_cone_the_node_sticks_and_on_it_the_force_is_mu_fN(gdim):
    directions = RNG.normal(size=(200, gdim))
    sizes = RNG.uniform(0.0, 1.0, size=200)
    trial = directions / np.linalg.norm(directions, axis=1)[:, None] * sizes[:, None]
    m = mapping_at(trial)
    inside = sizes <= 0.4
    assert np.all(m.state[inside] == STICK) and np.all(m.state[~inside] == SLIP)
    assert np.array_equal(m.force[inside], trial[inside])
    size = np.linalg.norm(m.force, axis=1)
    assert np.allclose(size[~inside], 0.4, rtol=1e-15)
    # the slipping force points along the trial force
    unit = trial[~inside] / np.linalg.norm(trial[~inside], axis=1)[:, None]
    assert np.allclose(m.force[~inside], 0.4 * unit, rtol=1e-14, atol=1e-15)


def test_a_node_out_of_contact_carries_nothing():
    m = mapping_at([[0.3, 0.0]], normal_force=0.0, active=False)
    assert m.state[0] == SEPARATED and np.all(m.force == 0) and np.all(m.tangent == 0)


@pytest.mark.parametrize("gdim", [2, 3])
def test_the_tangents_are_the_derivatives_of_the_force(gdim):
    """∂f_T/∂Δy_T = tangent·(ω_T ·) chain: f* = f0 + ω Δy; ∂f_T/∂f_N = normal_tangent."""
    law = CoulombFriction(0.4)
    weight, fN = 3.0, 1.0
    for size in (0.2, 1.7):             # stick, slip
        base = RNG.normal(size=gdim)
        base *= size / np.linalg.norm(base)
        dy = RNG.normal(size=gdim)
        h = 1e-7

        def force(y_scale, normal=fN):
            trial = (base + weight * y_scale * dy)[None]
            return law.return_mapping(trial, np.array([normal]), np.array([weight]),
                                      np.array([True])).force[0]

        m = law.return_mapping(base[None], np.array([fN]), np.array([weight]), np.array([True]))
        fd = (force(h) - force(-h)) / (2 * h)
        assert np.allclose(m.tangent[0] @ dy, fd, rtol=1e-7, atol=1e-9)
        fd_normal = (force(0.0, fN + h) - force(0.0, fN - h)) / (2 * h)
        assert np.allclose(m.normal_tangent[0], fd_normal, rtol=1e-7, atol=1e-9)


@pytest.mark.parametrize("mu, message", [(-0.1, "≥ 0"), (float("nan"), "finite"),
                                         (float("inf"), "finite"), ("0.3", "real number"),
                                         (True, "real number")])
def test_a_wrong_friction_coefficient_is_named(mu, message):
    with pytest.raises((ValueError, TypeError), match=message):
        CoulombFriction(mu)


@pytest.mark.parametrize("penalty", [0.0, -1.0, float("nan")])
def test_a_wrong_tangential_penalty_is_named(penalty):
    with pytest.raises(ValueError, match="tangential penalty"):
        CoulombFriction(0.3, tangential_penalty=penalty)


def test_the_default_tangential_penalty_is_a_tenth_of_the_normal_one():
    assert CoulombFriction(0.3).penalty(250.0) == 25.0
    assert CoulombFriction(0.3, 10.0).penalty(250.0) == 10.0
