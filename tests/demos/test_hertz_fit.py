"""The Hertz-profile estimator of peak pressure and contact size: exact on an
exact profile, and not swung by one outlying node."""
import numpy as np
import pytest

from demo_support.hertz_fit import fit_hertz_profile, hertz_profile

A, P0 = 0.3, 2.0


def _nodes(count: int = 61) -> np.ndarray:
    # graded towards the centre, out to 3a, as the demos' meshes
    return 3 * A * np.linspace(0.0, 1.0, count) ** 1.5


def test_exact_profile_is_recovered():
    r = _nodes()
    fit = fit_hertz_profile(r, hertz_profile(r, P0, A), a_hertz=1.1 * A)
    assert fit.p0 == pytest.approx(P0, rel=1e-8)
    assert fit.a == pytest.approx(A, rel=1e-8)
    assert fit.nodes == np.count_nonzero(r < 2 * 1.1 * A)


def test_one_outlying_node_does_not_swing_the_radius():
    r = _nodes()
    p = hertz_profile(r, P0, A)
    far = np.argmin(abs(r - 1.6 * A))
    p[far] = 0.05 * P0  # one small positive pressure far outside the zone
    fit = fit_hertz_profile(r, p, A)
    assert abs(fit.a / A - 1) < 0.02 and abs(fit.p0 / P0 - 1) < 0.02


def test_one_outlying_peak_does_not_swing_p0():
    r = _nodes()
    p = hertz_profile(r, P0, A)
    p[0] *= 1.3
    fit = fit_hertz_profile(r, p, A)
    assert fit.p_max == pytest.approx(1.3 * P0)
    assert abs(fit.p0 / P0 - 1) < 0.03


def test_bad_input_is_named():
    r = _nodes()
    with pytest.raises(ValueError, match="no positive pressure"):
        fit_hertz_profile(r, np.zeros_like(r), A)
    with pytest.raises(ValueError, match="distances"):
        fit_hertz_profile(r, np.ones(3), A)
    with pytest.raises(ValueError, match="a_hertz"):
        fit_hertz_profile(r, hertz_profile(r, P0, A), -1.0)
