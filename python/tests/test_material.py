"""Materials on arrays of F: stress is the derivative of energy, frame indifference, rest
state, inversion, and refused input."""
import numpy as np
import pytest

import piola

MODELS = ["rotated_linear", "corotated", "stvk", "neohookean", "spline", "muscle"]


def random_f(rng, n, spread=0.3):
    return np.eye(3) + spread * rng.standard_normal((n, 3, 3))


def random_rotation(rng):
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def fd_stress(mat, F, h=1e-6, **kw):
    """Central differences of the energy density over every entry of every F."""
    P = np.zeros_like(F)
    for i in range(3):
        for j in range(3):
            Fp, Fm = F.copy(), F.copy()
            Fp[:, i, j] += h
            Fm[:, i, j] -= h
            P[:, i, j] = (mat.energy_density(Fp, **kw) - mat.energy_density(Fm, **kw)) / (2 * h)
    return P


@pytest.mark.parametrize("model", MODELS)
def test_stress_is_energy_gradient(model):
    rng = np.random.default_rng(7)
    mat = piola.Material(model, youngs_modulus=2e5, poisson_ratio=0.35)
    F = random_f(rng, 200, 0.15)
    # above the model's (default) threshold, which the property reports
    F = F[np.linalg.svd(F, compute_uv=False).min(axis=1) > mat.inversion_threshold + 0.15]
    P = mat.stress(F)
    assert np.allclose(P, fd_stress(mat, F), rtol=1e-5, atol=1e-4 * mat.mu * 1e-3)


def test_muscle_fibre_stress_is_energy_gradient():
    rng = np.random.default_rng(3)
    mat = piola.Material("muscle", youngs_modulus=2e4, poisson_ratio=0.45,
                         muscle={"max_active_stress": 3e4, "passive_stiffness": 5e4})
    F = random_f(rng, 100, 0.1)
    fibers = rng.standard_normal((100, 3))
    fibers /= np.linalg.norm(fibers, axis=1)[:, None]
    for activation in (0.0, 0.7):
        P = mat.stress(F, fibers=fibers, activation=activation)
        fd = fd_stress(mat, F, fibers=fibers, activation=activation)
        assert np.allclose(P, fd, rtol=1e-5, atol=1e-3)
    # the fibres add tension along a stretched fibre
    stretch = np.diag([1.2, 1.0, 1.0])[None]
    along_x = np.array([[1.0, 0, 0]])
    iso = mat.stress(stretch)[0, 0, 0]
    active = mat.stress(stretch, fibers=along_x, activation=1.0)[0, 0, 0]
    assert active > iso
    # activation outside [0, 1] is refused, not clamped
    for bad in (2.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="activation must be in"):
            mat.stress(stretch, fibers=along_x, activation=bad)


@pytest.mark.parametrize("model", MODELS)
def test_rest_state_and_frame_indifference(model):
    rng = np.random.default_rng(11)
    mat = piola.Material(model)
    P0, psi0 = mat.evaluate(np.eye(3))
    assert np.abs(P0).max() < 1e-9 * mat.mu and abs(psi0) < 1e-9 * mat.mu
    F = random_f(rng, 50, 0.2)
    R = random_rotation(rng)
    P, psi = mat.evaluate(F)
    PR, psiR = mat.evaluate(R @ F)
    assert np.allclose(psiR, psi, rtol=1e-10, atol=1e-9 * mat.mu)
    assert np.allclose(PR, R @ P, rtol=1e-9, atol=1e-8 * mat.mu)
    assert P.shape == F.shape and psi.shape == (50,)


def test_lame_parameters_and_small_strain():
    mat = piola.Material("corotated", youngs_modulus=1e6, poisson_ratio=0.25)
    assert mat.mu == pytest.approx(1e6 / 2.5)
    assert mat.lam == pytest.approx(1e6 * 0.25 / (1.25 * 0.5))
    # uniaxial small strain with lateral contraction -nu eps: sigma_xx = E eps
    eps = 1e-6
    F = np.diag([1 + eps, 1 - 0.25 * eps, 1 - 0.25 * eps])
    assert mat.stress(F)[0, 0] == pytest.approx(1e6 * eps, rel=1e-4)


def test_inverted_elements_are_pushed_back():
    mat = piola.Material("neohookean")
    F = np.diag([1.0, 1.0, -0.3])
    U, fhat, V = piola.diagonalize(F)
    assert np.allclose(U @ np.diag(fhat) @ V.T, F, atol=1e-12)
    assert np.isclose(np.linalg.det(U), 1) and np.isclose(np.linalg.det(V), 1)
    assert fhat.min() < 0
    phat, psi, dphat = mat.diagonal(fhat)
    assert np.all(np.isfinite(phat)) and phat[np.argmin(fhat)] < 0
    # the derivative matches finite differences of the diagonal stress
    h = 1e-7
    for j in range(3):
        e = np.zeros(3)
        e[j] = h
        fd = (mat.diagonal(fhat + e)[0] - mat.diagonal(fhat - e)[0]) / (2 * h)
        assert np.allclose(dphat[:, j], fd, rtol=1e-5, atol=1e-3)
    # flat and collapsed elements give finite stress too
    P = mat.stress(np.stack([np.zeros((3, 3)), np.diag([1, 1, 0.0])]))
    assert np.all(np.isfinite(P))


def test_leading_dimensions_and_conversions():
    mat = piola.Material()
    F = np.tile(np.eye(3), (2, 4, 1, 1)) * 1.1
    P, psi = mat.evaluate(F)
    assert P.shape == (2, 4, 3, 3) and psi.shape == (2, 4)
    assert np.allclose(mat.stress(F.astype(np.float32)), P, rtol=1e-6)
    assert np.allclose(mat.stress(F.tolist()), P)
    assert np.allclose(mat.stress(np.asfortranarray(F[0])), P[0])


def test_misuse_raises():
    mat = piola.Material()
    with pytest.raises(ValueError, match="poisson_ratio"):
        piola.Material(poisson_ratio=0.7)
    with pytest.raises(ValueError, match="model"):
        piola.Material("rubber")
    with pytest.raises(ValueError, match="shape"):
        mat.stress(np.eye(4))
    with pytest.raises(TypeError, match="dtype"):
        mat.stress(np.eye(3, dtype=complex))
    with pytest.raises(TypeError):
        mat.stress("F")
    with pytest.raises(ValueError, match="finite"):
        mat.stress(np.full((3, 3), np.nan))
    with pytest.raises(ValueError, match="muscle"):
        mat.stress(np.eye(3)[None], fibers=np.ones((1, 3)))
    # the extension itself refuses what the package would have converted
    with pytest.raises(TypeError, match="dtype"):
        piola._piola.material_eval(mat._def, np.eye(3, dtype=np.float32)[None], None, 0.0)
    with pytest.raises(ValueError, match="C-contiguous"):
        piola._piola.material_eval(mat._def, np.zeros((2, 3, 3, 2))[..., 0], None, 0.0)
    with pytest.raises(ValueError):
        piola._piola.diagonalize(np.zeros((2, 3, 4)))


def test_rubber_and_artery_parameters_reach_the_model():
    """ogden, mooney_rivlin and hgo take their scene keys: the shear modulus follows from them
    (youngs_modulus is not used), and unknown or misplaced keys are refused by name."""
    og = piola.Material("ogden", poisson_ratio=0.45, ogden={"mu": [4e5, -2e4], "alpha": [2.0, -2.0]})
    assert og.mu == pytest.approx(0.5 * (4e5 * 2.0 + 2e4 * 2.0))
    mr = piola.Material("mooney_rivlin", poisson_ratio=0.45, mooney_rivlin={"c10": 2e5, "c01": 1e4})
    assert mr.mu == pytest.approx(2 * (2e5 + 1e4))
    # Mooney-Rivlin is the two-term Ogden model (2 C10, 2), (-2 C01, -2)
    twin = piola.Material("ogden", poisson_ratio=0.45, ogden={"mu": [4e5, -2e4], "alpha": [2, -2]})
    rng = np.random.default_rng(5)
    F = random_f(rng, 50, 0.1)
    assert np.allclose(piola.Material.from_dict(
        {"model": "mooney_rivlin", "poisson_ratio": 0.45,
         "mooney_rivlin": {"c10": 2e5, "c01": 1e4}}).stress(F), twin.stress(F), rtol=1e-9, atol=1e-6)
    h = piola.Material("hgo", poisson_ratio=0.45,
                       hgo={"mu": 7640, "k1": 996600, "k2": 524.6, "kappa": 0.226,
                            "fiber_angle_degrees": 49.98, "axis": [0, 0, 2]})
    assert h.mu == pytest.approx(7640)
    assert piola.Material("hgo").mu == pytest.approx(3000)  # HGO 2000's media by default
    with pytest.raises(ValueError, match="ogden parameters need model 'ogden'"):
        piola.Material("neohookean", ogden={"mu": [1e5], "alpha": [2]})
    with pytest.raises(ValueError, match="hgo.kappa"):
        piola.Material("hgo", hgo={"kappa": 0.5})
    with pytest.raises(ValueError, match="unknown key 'beta'"):
        piola.Material("hgo", hgo={"beta": 30})
    with pytest.raises(ValueError, match="hgo.fiber_stretch_limit"):
        piola.Material("hgo", hgo={"fiber_stretch_limit": 1.0})
    # past the fibre stretch limit the fibres are a spring of constant stiffness: a lower
    # limit gives less stress at a stretch beyond both
    along = np.diag([2.5, 1.0, 1.0])[None]
    fibre = np.array([[1.0, 0, 0]])
    assert (piola.Material("hgo", hgo={"fiber_stretch_limit": 1.2}).stress(along, fibers=fibre)[0, 0, 0]
            < piola.Material("hgo").stress(along, fibers=fibre)[0, 0, 0])
    with pytest.raises(ValueError, match="ogden.alpha"):
        piola.Material("ogden", ogden={"mu": [1e5, 2e3], "alpha": [2]})
    with pytest.raises(ValueError, match="c10 \\+ c01"):
        piola.Material("mooney_rivlin", mooney_rivlin={"c10": -1e4, "c01": 0})
    with pytest.raises(ValueError, match="unknown key"):
        piola.Material.from_dict({"model": "hgo", "hgo": {"k3": 1}})


@pytest.mark.parametrize("kappa", [0.0, 0.226])
def test_hgo_fibre_stress_is_energy_gradient(kappa):
    """With fibres the stress is the gradient of the whole energy (matrix and both families),
    the fibres stiffen the response along them, and a fibre along the axis is refused."""
    rng = np.random.default_rng(11)
    mat = piola.Material("hgo", poisson_ratio=0.45,
                         hgo={"k1": 2e4, "k2": 2.0, "kappa": kappa, "fiber_angle_degrees": 35})
    F = random_f(rng, 80, 0.2)
    # above HGO's default threshold at its highest (0.5 once J has fallen, materials.md), where
    # no entry is clamped and the stress is the energy's gradient
    F = F[np.linalg.svd(F, compute_uv=False).min(axis=1) > 0.55]
    fibers = rng.standard_normal((len(F), 3))
    fibers[:, 0] += 0.5  # never along the axis z
    P = mat.stress(F, fibers=fibers)
    assert np.allclose(P, fd_stress(mat, F, fibers=fibers), rtol=1e-5, atol=1e-2)
    stretch = np.diag([1.3, 1.0, 1.0])[None]
    with_fibres = mat.stress(stretch, fibers=np.array([[1.0, 0, 0]]))[0, 0, 0]
    assert with_fibres > mat.stress(stretch)[0, 0, 0]
    with pytest.raises(ValueError, match="parallel"):
        mat.stress(stretch, fibers=np.array([[0, 0, 1.0]]))
