"""User-supplied stiffness matrices: accepted when physical, refused with one clear line."""

from __future__ import annotations

import numpy as np
import pytest

from taos.errors import InputError
from taos.fem import load_gimbal_stiffness, load_stiffness_matrix, rigid_body_modes, validate_stiffness_matrix


def spd6(seed=0):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(6, 6))
    return A @ A.T + 6 * np.eye(6)


def free12():
    refs = np.array([[0, 0, 0.0], [0, 0, 0.145]])
    R = rigid_body_modes(refs)
    P = np.eye(12) - R @ np.linalg.pinv(R)  # projector onto the complement of rigid motions
    A = np.diag(np.r_[np.full(6, 1e9), np.full(6, 1e7)])
    return P @ A @ P


def one_line(err: InputError) -> str:
    msg = str(err)
    assert "\n" not in msg
    return msg


def test_good_npz_and_csv_are_accepted(tmp_path):
    Ku, Kl = spd6(1), spd6(2)
    np.savez(tmp_path / "g.npz", K_upper=Ku, K_lower=Kl, K_upper_free=free12(), K_lower_free=free12())
    g = load_gimbal_stiffness(tmp_path / "g.npz")
    assert np.allclose(g.K_upper, Ku) and g.K_lower_free.shape == (12, 12)
    np.savetxt(tmp_path / "g.csv", np.vstack([Ku, Kl]), delimiter=",", header="K_upper over K_lower")
    g2 = load_gimbal_stiffness(tmp_path / "g.csv")
    assert np.allclose(g2.K_lower, Kl)
    np.savetxt(tmp_path / "k.csv", free12(), delimiter=",")
    assert load_stiffness_matrix(tmp_path / "k.csv", kind="free").shape == (12, 12)


def test_asymmetric_matrix_is_refused_naming_file_and_field(tmp_path):
    K = spd6()
    K[0, 1] += 0.5 * abs(K[0, 1]) + 1.0
    np.savez(tmp_path / "bad.npz", K_upper=K, K_lower=spd6())
    with pytest.raises(InputError) as e:
        load_gimbal_stiffness(tmp_path / "bad.npz")
    msg = one_line(e.value)
    assert "bad.npz" in msg and "K_upper" in msg and "symmetric" in msg


def test_indefinite_matrix_is_refused(tmp_path):
    K = spd6()
    w, V = np.linalg.eigh(K)
    w[0] = -w[-1] * 0.1
    np.savez(tmp_path / "neg.npz", K_upper=spd6(), K_lower=(V * w) @ V.T)
    with pytest.raises(InputError) as e:
        load_gimbal_stiffness(tmp_path / "neg.npz")
    msg = one_line(e.value)
    assert "K_lower" in msg and "positive definite" in msg


def test_wrong_shape_is_refused(tmp_path):
    np.savetxt(tmp_path / "k.csv", np.eye(5), delimiter=",")
    with pytest.raises(InputError) as e:
        load_stiffness_matrix(tmp_path / "k.csv")
    assert "6x6" in one_line(e.value) and "(5, 5)" in str(e.value)
    np.savetxt(tmp_path / "g.csv", np.eye(6), delimiter=",")
    with pytest.raises(InputError, match="12 rows x 6 columns"):
        load_gimbal_stiffness(tmp_path / "g.csv")


def test_nan_is_refused():
    K = spd6()
    K[2, 2] = np.nan
    with pytest.raises(InputError, match="finite"):
        validate_stiffness_matrix(K, source="user.npz", field="K_upper", kind="held")


def test_free_free_matrix_needs_exactly_six_rigid_body_zero_modes():
    K = free12() + 1e6 * np.eye(12)  # grounded: no zero modes
    with pytest.raises(InputError, match="0 zero eigenvalues"):
        validate_stiffness_matrix(K, source="user.npz", field="K_upper_free", kind="free")


def test_singular_held_matrix_is_refused():
    K = spd6()
    K[5, :] = K[:, 5] = 0.0
    with pytest.raises(InputError, match="positive diagonal"):
        validate_stiffness_matrix(K, source="u.csv", field="K", kind="held")


def test_missing_file_and_missing_key_are_one_line(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        load_gimbal_stiffness(tmp_path / "nope.npz")
    np.savez(tmp_path / "g.npz", K_upper=spd6())
    with pytest.raises(InputError, match="K_lower: expected a 6x6 stiffness matrix, got missing key"):
        load_gimbal_stiffness(tmp_path / "g.npz")
