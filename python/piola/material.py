"""Constitutive models on arrays of deformation gradients (docs/materials.md)."""
from . import _piola
from ._convert import check_keys, float_array, float_stack, number

_DEFAULT = _piola.defaults()["material"]
_SPLINE_KEYS = ("compression_stretch", "elongation_stretch", "stiffening")
_MUSCLE_KEYS = ("passive_stiffness", "passive_toe_stretch", "max_active_stress",
                "optimal_stretch", "active_width")
_MOONEY_KEYS = ("c10", "c01")
_HGO_KEYS = ("mu", "k1", "k2", "kappa", "fiber_angle_degrees")


def _ogden(values):
    """{"mu": [Pa, ...], "alpha": [...]} (the scene keys) as two tuples of numbers."""
    if values is None:
        return _DEFAULT[7]
    check_keys(values, ("mu", "alpha"), "ogden")
    out = []
    for key in ("mu", "alpha"):
        if key not in values:
            raise ValueError(f"ogden.{key} is required")
        terms = values[key]
        if isinstance(terms, (str, bytes)) or not hasattr(terms, "__len__"):
            raise ValueError(f"ogden.{key} must be a list of 1 to 6 numbers")
        out.append(tuple(number(v, f"ogden.{key}[{i}]") for i, v in enumerate(terms)))
    return tuple(out)


def _hgo(values):
    """{"mu", "k1", "k2", "kappa", "fiber_angle_degrees", "axis", "fiber_stretch_limit"}
    (the scene keys)."""
    if values is None:
        return _DEFAULT[9]
    check_keys(values, _HGO_KEYS + ("axis", "fiber_stretch_limit"), "hgo")
    scalars = tuple(number(values.get(k, d), f"hgo.{k}") for k, d in zip(_HGO_KEYS, _DEFAULT[9]))
    axis = values.get("axis", _DEFAULT[9][5])
    if isinstance(axis, (str, bytes)) or not hasattr(axis, "__len__") or len(axis) != 3:
        raise ValueError("hgo.axis must be 3 numbers")
    limit = number(values.get("fiber_stretch_limit", _DEFAULT[9][6]), "hgo.fiber_stretch_limit")
    return scalars + (tuple(number(a, "hgo.axis") for a in axis), limit)


def _sub(values, keys, defaults, what):
    if values is None:
        return tuple(defaults)
    check_keys(values, keys, what)
    return tuple(number(values.get(k, d), f"{what}.{k}") for k, d in zip(keys, defaults))


class Material:
    """A constitutive model (docs/materials.md), extended through inversion.

    Material(model="neohookean", youngs_modulus=1e5 Pa, poisson_ratio=0.3,
             inversion_threshold=0, inversion_mode="default", spline=None, muscle=None,
             ogden=None, mooney_rivlin=None, hgo=None)
    inversion_threshold 0 and inversion_mode "default" take the model's own defaults
    (docs/materials.md, "Defaults that recover"); the properties give the values in force.
    `spline`, `muscle`, `ogden`, `mooney_rivlin` and `hgo` are dicts with the scene keys of
    docs/scene-format.md, each for its own model only. Invalid parameters raise ValueError
    naming the parameter."""

    def __init__(self, model=_DEFAULT[0], youngs_modulus=_DEFAULT[1], poisson_ratio=_DEFAULT[2],
                 inversion_threshold=_DEFAULT[3], inversion_mode=_DEFAULT[4], spline=None,
                 muscle=None, ogden=None, mooney_rivlin=None, hgo=None):
        if not isinstance(model, str) or not isinstance(inversion_mode, str):
            raise TypeError("model and inversion_mode are strings")
        for name, values in (("spline", spline), ("muscle", muscle), ("ogden", ogden),
                             ("mooney_rivlin", mooney_rivlin), ("hgo", hgo)):
            if values is not None and model != name:
                raise ValueError(f"{name} parameters need model '{name}'")
        self._def = (model, number(youngs_modulus, "youngs_modulus"),
                     number(poisson_ratio, "poisson_ratio"),
                     number(inversion_threshold, "inversion_threshold"), inversion_mode,
                     _sub(spline, _SPLINE_KEYS, _DEFAULT[5], "spline"),
                     _sub(muscle, _MUSCLE_KEYS, _DEFAULT[6], "muscle"), _ogden(ogden),
                     _sub(mooney_rivlin, _MOONEY_KEYS, _DEFAULT[8], "mooney_rivlin"), _hgo(hgo))
        self._lame = _piola.material_check(self._def)

    @classmethod
    def from_dict(cls, d):
        """From a scene's `material` object (model, youngs_modulus, poisson_ratio,
        inversion {threshold, mode}, spline, muscle, ogden, mooney_rivlin, hgo);
        stiffness_scale is a solid's, not a material's, and is refused here."""
        check_keys(d, ("model", "youngs_modulus", "poisson_ratio", "inversion", "spline",
                       "muscle", "ogden", "mooney_rivlin", "hgo"), "material")
        inv = d.get("inversion", {})
        check_keys(inv, ("threshold", "mode"), "material.inversion")
        return cls(d.get("model", _DEFAULT[0]), d.get("youngs_modulus", _DEFAULT[1]),
                   d.get("poisson_ratio", _DEFAULT[2]), inv.get("threshold", _DEFAULT[3]),
                   inv.get("mode", _DEFAULT[4]), d.get("spline"), d.get("muscle"),
                   d.get("ogden"), d.get("mooney_rivlin"), d.get("hgo"))

    model = property(lambda self: self._def[0], doc="model name")
    youngs_modulus = property(lambda self: self._def[1], doc="Pa")
    poisson_ratio = property(lambda self: self._def[2], doc="dimensionless")
    inversion_threshold = property(lambda self: self._lame["threshold"],
                                   doc="dimensionless, in force (the model's default if unset)")
    inversion_mode = property(lambda self: self._lame["inversion_mode"],
                              doc="'linear', 'clamp' or 'energy', in force")
    mu = property(lambda self: self._lame["mu"], doc="shear modulus (Lame mu), Pa")
    lam = property(lambda self: self._lame["lambda"], doc="Lame lambda, Pa")

    def __repr__(self):
        return (f"Material({self.model!r}, youngs_modulus={self.youngs_modulus:g}, "
                f"poisson_ratio={self.poisson_ratio:g})")

    def evaluate(self, F, fibers=None, activation=0.0):
        """(P, psi): the first Piola-Kirchhoff stress (Pa, shape (..., 3, 3)) and the energy
        density (J/m^3, shape (...)) at deformation gradients F of shape (..., 3, 3).
        fibers (..., 3), for the muscle and hgo models: each F's fibre direction in material
        space (for hgo the bisector of its two families); activation in [0, 1] (muscle)."""
        F = float_stack(F, "F", (3, 3))
        lead = F.shape[:-2]
        flat = F.reshape(-1, 3, 3)
        fib = None
        if fibers is not None:
            fib = float_array(fibers, "fibers", lead + (3,)).reshape(-1, 3)
        activation = number(activation, "activation")
        if not 0.0 <= activation <= 1.0:  # NaN included
            raise ValueError(f"activation must be in [0, 1], got {activation!r}")
        P, psi = _piola.material_eval(self._def, flat, fib, activation)
        return P.reshape(lead + (3, 3)), psi.reshape(lead)

    def stress(self, F, fibers=None, activation=0.0):
        """First Piola-Kirchhoff stress P (Pa) at F (..., 3, 3)."""
        return self.evaluate(F, fibers, activation)[0]

    def energy_density(self, F, fibers=None, activation=0.0):
        """Energy density psi (J/m^3) at F (..., 3, 3)."""
        return self.evaluate(F, fibers, activation)[1]

    def diagonal(self, fhat):
        """(phat, psi, dphat) at diagonal deformations fhat (..., 3): the diagonal stress (Pa),
        the energy density (J/m^3) and dphat_i/dfhat_j (Pa, (..., 3, 3))."""
        h = float_stack(fhat, "fhat", (3,))
        lead = h.shape[:-1]
        p, psi, dp = _piola.material_eval_hat(self._def, h.reshape(-1, 3))
        return p.reshape(lead + (3,)), psi.reshape(lead), dp.reshape(lead + (3, 3))


def diagonalize(F):
    """(U, fhat, V) with F = U diag(fhat) V^T, U and V rotations, for F of shape (..., 3, 3)
    (paper section 5; inverted F gets one negative entry of fhat)."""
    F = float_stack(F, "F", (3, 3))
    lead = F.shape[:-2]
    U, h, V = _piola.diagonalize(F.reshape(-1, 3, 3))
    return U.reshape(lead + (3, 3)), h.reshape(lead + (3,)), V.reshape(lead + (3, 3))
