"""The impact laws' names in Python (issue 24, item 8): `lcsim.impacts` keys each
result by the law's own name, so the alias 'moreau' gives 'newton'; 'inelastic' is
Moreau's rule whatever the restitution; a run with the alias reports 'newton'."""

import numpy as np
import pytest

import lcsim

TOL = 1e-14  # Example 3.8.3 / 1.4.1: a few flops on small integers


def test_impact_law_names_are_the_laws(robots):
    names = lcsim.impact_law_names()
    assert "newton" in names and "inelastic" in names
    assert "moreau" not in names  # an alias, not a law of its own
    model = lcsim.load(robots / "two_carts_hook.yaml")
    results = lcsim.impacts(model, [0, 0, -1, 2], rules=["moreau"])
    assert list(results) == ["newton"]
    assert results["newton"].ok
    # Example 3.8.3 (restitution 0): the hook alone.
    np.testing.assert_allclose(results["newton"].v_after, [0.5, 0.5], atol=TOL)


def test_inelastic_ignores_the_restitution(robots):
    """Example 3.8.3 with e = 1/2 on both contacts: 'inelastic' still gives Moreau's
    jump v+ = (1/2, 1/2); 'newton' applies (1 + e) to the hook's impulse."""
    model = lcsim.load(robots / "two_carts_hook.yaml")
    r = lcsim.impacts(model, [0, 0, -1, 2], rules=["inelastic", "newton"],
                      restitution=[0.5, 0.5])
    np.testing.assert_allclose(r["inelastic"].v_after, [0.5, 0.5], atol=TOL)
    np.testing.assert_allclose(r["inelastic"].impulse, [0.0, 1.5], atol=TOL)
    np.testing.assert_allclose(r["newton"].impulse, [0.0, 2.25], atol=TOL)


def test_a_run_with_the_alias_reports_newton(robots):
    model = lcsim.load(robots / "two_carts_hook.yaml")
    run = lcsim.simulate(model, t_end=0.1, impact="moreau")
    assert run.ok and run.impact_law == "newton"
    with pytest.raises(lcsim.InputError, match="alias moreau"):
        lcsim.simulate(model, t_end=0.1, impact="bogus")
