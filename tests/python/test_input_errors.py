"""Bad input from Python raises lcsim.InputError carrying the library's message, the
same line the command line prints for the same input."""

import subprocess

import numpy as np
import pytest
import scipy.sparse

import lcsim


def cli_error(lcsim_binary, *args):
    r = subprocess.run([str(lcsim_binary), *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 2, r.stderr
    return r.stderr


def test_unknown_method_names_it(robots, lcsim_binary):
    model = lcsim.load(robots / "two_carts.yaml")
    with pytest.raises(lcsim.InputError) as e:
        lcsim.simulate(model, method="nosuch")
    assert "nosuch" in str(e.value)
    assert str(e.value) in cli_error(lcsim_binary, "simulate", robots / "two_carts.yaml",
                                     "--method", "nosuch")


def test_missing_file_names_it(tmp_path, lcsim_binary):
    missing = tmp_path / "missing.yaml"
    with pytest.raises(lcsim.InputError) as e:
        lcsim.load(missing)
    assert str(missing) in str(e.value)
    assert str(e.value) in cli_error(lcsim_binary, "simulate", missing)


def test_infeasible_start_names_the_constraint(robots, lcsim_binary):
    model = lcsim.load(robots / "two_carts.yaml")
    with pytest.raises(lcsim.InputError) as e:
        lcsim.simulate(model, x0=[-0.5, 0, 0, 0])
    assert "stop" in str(e.value)
    assert str(e.value) in cli_error(lcsim_binary, "simulate", robots / "two_carts.yaml",
                                     "--x0", "-0.5,0,0,0")


def test_option_the_method_does_not_read(robots):
    model = lcsim.load(robots / "two_carts.yaml")
    with pytest.raises(lcsim.InputError, match="theta"):
        lcsim.simulate(model, theta=0.7)  # the exact method has no theta


def test_bad_matrices_name_the_field():
    with pytest.raises(lcsim.InputError, match=r"mechanical\.M.*symmetric"):
        lcsim.Model.mechanical(np.array([[1.0, 0.5], [0.0, 1.0]]), E=np.array([[1.0, 0.0]]))
    with pytest.raises(lcsim.InputError, match=r"mechanical\.E"):
        lcsim.Model.mechanical(np.eye(2), E=np.ones((1, 3)))
    with pytest.raises(lcsim.InputError, match=r"mechanical\.restitution"):
        lcsim.Model.mechanical(np.eye(2), E=np.array([[1.0, 0.0]]), restitution=[1.5])
    with pytest.raises(lcsim.InputError, match=r"mechanical\.M"):
        lcsim.Model.mechanical(scipy.sparse.csc_matrix(np.diag([1.0, -1.0])))


def test_bad_restitution_names_it(robots):
    """The library's check of a model's restitution (in [0, 1], one per constraint)."""
    model = lcsim.load(robots / "two_carts_hook.yaml")
    with pytest.raises(lcsim.InputError, match=r"mechanical\.restitution.*2"):
        lcsim.impacts(model, [0, 0, -1, 2], restitution=[2.0, 0.0])
    with pytest.raises(lcsim.InputError, match=r"mechanical\.restitution"):
        lcsim.impacts(model, [0, 0, -1, 2], restitution=[0.5])


def test_bad_lcp():
    with pytest.raises(lcsim.InputError):
        lcsim.solve_lcp(np.eye(2), [1.0, 2.0, 3.0])
    with pytest.raises(lcsim.InputError, match="nosuch"):
        lcsim.solve_lcp(np.eye(2), [1.0, 2.0], solver="nosuch")


def test_numerical_trouble_is_a_status():
    """An infeasible LCP (z >= 0 with -z - 1 >= 0 has no solution): Lemke ends on a
    ray, a status on the result, not an exception."""
    r = lcsim.solve_lcp(np.array([[-1.0]]), [-1.0], solver="lemke")
    assert r.status == "ray termination" and not r.ok


def test_sparse_and_dense_give_the_same_model():
    K = np.array([[2.0, -1.0], [-1.0, 1.0]])
    E = np.array([[1.0, 0.0]])
    dense = lcsim.Model.mechanical(np.eye(2), K, E)
    sparse = lcsim.Model.mechanical(scipy.sparse.identity(2, format="csc"),
                                    scipy.sparse.csr_matrix(K), scipy.sparse.coo_matrix(E))
    a = lcsim.simulate(dense, x0=[0.5, 0, -1, 0], t_end=2.0, dt_out=0.1)
    b = lcsim.simulate(sparse, x0=[0.5, 0, -1, 0], t_end=2.0, dt_out=0.1)
    assert a.to_csv() == b.to_csv()


def test_large_arrays_are_not_copied():
    """The sample arrays view the buffers the run filled (a capsule owns them): numpy
    does not own a copy, and q, v are views of x."""
    model = lcsim.Model.mechanical(np.eye(2), np.array([[2.0, -1.0], [-1.0, 1.0]]),
                                   np.array([[1.0, 0.0]]))
    run = lcsim.simulate(model, x0=[0.5, 0, 0, 0], t_end=1.0, dt_out=0.01)
    assert not run.x.flags.owndata and run.x.base is not None
    assert np.shares_memory(run.q, run.x) and np.shares_memory(run.v, run.x)
    assert run.x is run.x  # the same array on each access, not a new copy
