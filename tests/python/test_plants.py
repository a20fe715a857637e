# SPDX-License-Identifier: Apache-2.0
"""The registry plants (sim_host/src/plants/) against equations of motion derived here a second,
independent way, with numpy only: each body is a set of point masses placed by the plant's
geometry (a thin uniform rod as its two Gauss-Legendre points, exact for the quadratic kinetic
energy density along it), the mass matrix is sum m J^T J with the Jacobians J taken by complex
step, the Coriolis terms come from finite differences of that matrix, gravity from the complex-
step gradient of the potential. Checked: the state derivative at random states, inputs and
parameters; the energy function; energy conservation over a long frictionless run; the
linearisation of the C step at the upright against the one of these equations.
"""
import ctypes

import numpy as np
import pytest

from icoac.core import binding as B

G_POINTS = (0.5 - 0.5 / np.sqrt(3.0), 0.5 + 0.5 / np.sqrt(3.0))  # Gauss-Legendre on [0, 1], weights 1/2


# -- geometry of each plant: generalised coordinates q -> [(mass, position)] ------------------------
def rod(mass, base, direction, length):
    """A thin uniform rod from base along the unit vector direction, as two point masses."""
    return [(mass / 2.0, base + g * length * direction) for g in G_POINTS]


def cart_pole_bodies(p, q):
    x, th = q
    cart = np.array([x, 0.0 * x, 0.0 * x])
    pole = np.array([np.sin(th), 0.0 * th, np.cos(th)])
    return [(p["cart_mass"], cart)] + rod(p["pole_mass"], cart, pole, 2.0 * p["half_length"])


def furuta_bodies(p, q):
    th, al = q
    radial = np.array([np.cos(th), np.sin(th), 0.0 * th])
    tangent = np.array([-np.sin(th), np.cos(th), 0.0 * th])
    up = np.array([0.0, 0.0, 1.0]) + 0.0 * th
    tip = p["arm_length"] * radial
    pendulum = np.sin(al) * tangent + np.cos(al) * up
    return (rod(p["arm_mass"], 0.0 * tip, radial, p["arm_length"]) +
            rod(p["pendulum_mass"], tip, pendulum, p["pendulum_length"]))


def double_cart_pole_bodies(p, q):
    x, t1, t2 = q
    cart = np.array([x, 0.0 * x, 0.0 * x])
    d1 = np.array([np.sin(t1), 0.0 * t1, np.cos(t1)])
    d2 = np.array([np.sin(t2), 0.0 * t2, np.cos(t2)])
    joint = cart + p["length1"] * d1
    return ([(p["cart_mass"], cart)] + rod(p["mass1"], cart, d1, p["length1"]) +
            rod(p["mass2"], joint, d2, p["length2"]))


def furuta_forces(p, q, qd, u):
    """Generalised forces besides gravity: the motor (its voltage saturated, back-EMF included) and
    viscous friction."""
    k, r = p["torque_constant"], p["resistance"]
    u = np.clip(u, -p["max_voltage"], p["max_voltage"])
    return np.array([k * (u - k * qd[0]) / r - p["arm_damping"] * qd[0], -p["pendulum_damping"] * qd[1]])


PLANTS = {
    # name: (bodies, extra rotor inertia on q[0], non-gravity forces)
    "cart_pole": (cart_pole_bodies, lambda p: 0.0, lambda p, q, qd, u: np.array([u, 0.0])),
    "furuta": (furuta_bodies, lambda p: p["hub_inertia"], furuta_forces),
    "double_cart_pole": (double_cart_pole_bodies, lambda p: 0.0, lambda p, q, qd, u: np.array([u, 0.0, 0.0])),
}


# -- Lagrangian mechanics from the geometry --------------------------------------------------------
def jacobians(bodies, p, q):
    """[(mass, d position / d q)] by complex step (exact to rounding)."""
    h = 1e-30
    n = len(q)
    masses = [m for m, _ in bodies(p, np.asarray(q, dtype=float))]
    cols = []
    for j in range(n):
        qc = np.asarray(q, dtype=complex)
        qc[j] += 1j * h
        cols.append([pos.imag / h for _, pos in bodies(p, qc)])
    return [(masses[k], np.array([cols[j][k] for j in range(n)]).T) for k in range(len(masses))]


def mass_matrix(name, p, q):
    bodies, rotor, _ = PLANTS[name]
    m = sum(mass * jac.T @ jac for mass, jac in jacobians(bodies, p, q))
    m[0, 0] += rotor(p)
    return m


def potential(name, p, q):
    bodies = PLANTS[name][0]
    return sum(mass * p["gravity"] * pos[2] for mass, pos in bodies(p, q))


def potential_gradient(name, p, q):
    h = 1e-30
    out = np.zeros(len(q))
    for j in range(len(q)):
        qc = np.asarray(q, dtype=complex)
        qc[j] += 1j * h
        out[j] = potential(name, p, qc).imag / h
    return out


def accelerations(name, p, q, qd, u):
    """q'' = M^-1 (Q - (dM/dt) q' + 1/2 d(q'^T M q')/dq - dV/dq)."""
    n = len(q)
    h = 1e-6
    dm = []  # dM/dq_k by central differences
    for k in range(n):
        e = np.zeros(n)
        e[k] = h
        dm.append((mass_matrix(name, p, q + e) - mass_matrix(name, p, q - e)) / (2 * h))
    m_dot = sum(dm[k] * qd[k] for k in range(n))
    quad = np.array([qd @ dm[k] @ qd for k in range(n)])
    rhs = PLANTS[name][2](p, q, qd, u) - m_dot @ qd + 0.5 * quad - potential_gradient(name, p, q)
    return np.linalg.solve(mass_matrix(name, p, q), rhs)


def energy(name, p, q, qd):
    return 0.5 * qd @ mass_matrix(name, p, q) @ qd + potential(name, p, q)


# -- the C side --------------------------------------------------------------------------------------
def params_of(model, info):
    return {pr["name"]: model.param[i] for i, pr in enumerate(info["params"])}


def split(state, n_state):
    """C state (q0, q0', q1, q1', ...) -> (q, q')."""
    s = np.asarray(state[:n_state])
    return s[0::2].copy(), s[1::2].copy()


def c_derivatives(model, state, u):
    ds = np.zeros(B.MAX_STATE)
    B.check_status(B.lib.icoac_sim_model_derivatives(ctypes.byref(model), np.ascontiguousarray(state), u, ds))
    return ds


def c_step(model, state, u):
    s = np.array(state, dtype=float)
    B.check_status(B.lib.icoac_sim_model_step(ctypes.byref(model), s, u))
    return s


def c_energy(model, state):
    e = ctypes.c_double()
    B.check_status(B.lib.icoac_sim_model_energy(ctypes.byref(model), np.ascontiguousarray(state), ctypes.byref(e)))
    return e.value


def random_model(name, rng):
    """Default parameters scaled by U(0.5, 2) each (limits and gravity kept), so that every
    parameter's place in the equations is tested, not only the default values."""
    info = B.plant_info(name)
    model = B.model_default(name)
    for i, pr in enumerate(info["params"]):
        if "limit" not in pr["name"] and pr["name"] != "gravity":
            value = pr["value"] if pr["value"] != 0.0 else 1e-3  # friction: nonzero here
            model.param[i] = min(value * rng.uniform(0.5, 2.0), pr["max"])  # a max_force of 1e6 stays
    B.check_status(B.lib.icoac_sim_model_check(ctypes.byref(model)))
    return model, info


def random_state(rng, n_state, angle=1.2, rate=3.0):
    s = np.zeros(B.MAX_STATE)
    s[:n_state] = rng.uniform(-1, 1, n_state) * np.tile([angle, rate], n_state // 2)
    return s


NAMES = list(PLANTS)


def test_registry_holds_the_plants_derived_here():
    """The plants derived here are in the registry (it may hold more: a plant added to it needs no
    line here); their data sources' values."""
    names = [B.plant_info(i)["name"] for i in range(B.lib.icoac_sim_plant_count())]
    assert set(NAMES) <= set(names) and names[B.CART_POLE] == "cart_pole"
    furuta = B.plant_info("furuta")
    assert furuta["input"] == ("voltage", "V")
    values = {pr["name"]: pr["value"] for pr in furuta["params"]}
    # QUBE-Servo 2: rotary pendulum module and motor (docs/plants.md)
    assert (values["arm_mass"], values["arm_length"], values["pendulum_mass"], values["pendulum_length"]) == \
        (0.095, 0.085, 0.024, 0.129)
    assert (values["resistance"], values["torque_constant"]) == (8.4, 0.042)
    dip = B.plant_info("double_cart_pole")
    values = {pr["name"]: pr["value"] for pr in dip["params"]}
    assert [values[k] for k in ("cart_mass", "mass1", "mass2", "length1", "length2")] == [1.5, 0.5, 0.75, 0.5, 0.75]
    with pytest.raises(B.ConfigError, match="unknown plant 'nope'"):
        B.plant_index("nope")
    with pytest.raises(B.ConfigError, match="no parameter"):
        B.model_default("furuta", half_length=1.0)
    with pytest.raises(B.ConfigError):
        B.model_default("furuta", pendulum_mass=-1.0)


@pytest.mark.parametrize("name", NAMES)
def test_derivatives_match_the_lagrangian(name):
    rng = np.random.default_rng(12345)
    for trial in range(40):
        model, info = random_model(name, rng) if trial else (B.model_default(name), B.plant_info(name))
        p = params_of(model, info)
        n = len(info["state"])
        state = random_state(rng, n)
        u = rng.uniform(-10, 10)
        q, qd = split(state, n)
        expected = accelerations(name, p, q, qd, u)
        ds = c_derivatives(model, state, u)
        assert np.array_equal(ds[0:n:2], qd)  # d/dt position = velocity
        scale = max(1.0, np.max(np.abs(expected)))
        assert np.allclose(ds[1:n:2], expected, rtol=0, atol=1e-7 * scale), (name, trial, ds[1:n:2], expected)


@pytest.mark.parametrize("name", NAMES)
def test_energy_function(name):
    rng = np.random.default_rng(7)
    info = B.plant_info(name)
    n = len(info["state"])
    assert info["has_energy"]
    for _ in range(20):
        model, info = random_model(name, rng)
        state = random_state(rng, n)
        q, qd = split(state, n)
        assert c_energy(model, state) == pytest.approx(energy(name, params_of(model, info), q, qd), rel=1e-12, abs=1e-15)


@pytest.mark.parametrize("name", NAMES)
def test_energy_conserved_without_input_and_friction(name):
    """RK4 at 0.5 ms for 10 s from a tilted start, no input, no friction (the Furuta motor
    disconnected): the energy of the equations derived here drifts by less than 1e-7 of the
    potential energy's range, while the state travels far."""
    info = B.plant_info(name)
    n = len(info["state"])
    free = {pr["name"]: 0.0 for pr in info["params"]
            if pr["name"] in ("torque_constant", "arm_damping", "pendulum_damping")}
    free.update({pr["name"]: pr["max"] for pr in info["params"] if "limit" in pr["name"]})
    model = B.model_default(name, integrator="rk4", dt=5e-4, **free)
    p = params_of(model, info)
    state = np.zeros(B.MAX_STATE)
    state[:n] = [0.2, -0.3, 0.4, 0.5, -0.3, 0.2][:n]
    e0 = energy(name, p, *split(state, n))
    hanging = np.array([0.0, np.pi, np.pi][: n // 2])  # (x or theta, then the links' angles)
    scale = abs(potential(name, p, np.zeros(n // 2)) - potential(name, p, hanging))
    start = state.copy()
    drift = 0.0
    for k in range(20000):
        state = c_step(model, state, 0.0)
        if k % 500 == 499:
            drift = max(drift, abs(energy(name, p, *split(state, n)) - e0))
    assert drift < 1e-7 * scale, (name, drift, scale)
    assert np.max(np.abs(state[:n] - start[:n])) > 0.1
    # With Euler at 10 ms the same run gains energy: the check can fail.
    model.integrator, model.dt = B.INTEGRATORS["euler"], 0.01
    state = start.copy()
    for _ in range(200):
        state = c_step(model, state, 0.0)
    assert abs(energy(name, p, *split(state, n)) - e0) > 1e-5 * scale


def test_furuta_motor_brakes():
    """Motor connected at 0 V: the back-EMF only dissipates, dE/dt = -k^2/R theta_dot^2 <= 0."""
    model = B.model_default("furuta", integrator="rk4", dt=1e-3, arm_limit=1e6, pendulum_limit=np.pi)
    info = B.plant_info("furuta")
    p = params_of(model, info)
    state = np.zeros(B.MAX_STATE)
    state[:4] = [0.0, 2.0, 0.3, 0.0]
    e = [energy("furuta", p, *split(state, 4))]
    for _ in range(2000):
        state = c_step(model, state, 0.0)
        e.append(energy("furuta", p, *split(state, 4)))
    assert np.all(np.diff(e) <= 1e-12) and e[-1] < e[0] - 1e-4


def rk4_discrete(a, b, dt):
    """The RK4 step of x' = A x + B u: exactly the Taylor polynomial of degree 4."""
    ha = dt * a
    eye = np.eye(len(a))
    ad = eye + ha + ha @ ha / 2 + ha @ ha @ ha / 6 + ha @ ha @ ha @ ha / 24
    bd = dt * (eye + ha / 2 + ha @ ha / 6 + ha @ ha @ ha / 24) @ b
    return ad, bd


def upright_linearisation(name, model, info):
    """Continuous A, B at the upright in the C state order (q0, q0', q1, q1', ...): M0 q'' =
    -K q - D q' + Bq u with M0 = M(0), K the Hessian of V, D and Bq from the generalised forces."""
    p = params_of(model, info)
    n = len(info["state"])
    dof = n // 2
    m0 = mass_matrix(name, p, np.zeros(dof))
    h = 1e-5
    k = np.zeros((dof, dof))
    for j in range(dof):
        e = np.zeros(dof)
        e[j] = h
        k[:, j] = (potential_gradient(name, p, e) - potential_gradient(name, p, -e)) / (2 * h)
    forces = PLANTS[name][2]
    zero = np.zeros(dof)
    bq = forces(p, zero, zero, 1.0) - forces(p, zero, zero, 0.0)
    d = -np.array([forces(p, zero, np.eye(dof)[j], 0.0) for j in range(dof)]).T
    inv = np.linalg.inv(m0)
    a = np.zeros((n, n))
    bvec = np.zeros((n, 1))
    for i in range(dof):
        a[2 * i, 2 * i + 1] = 1.0
        for j in range(dof):
            a[2 * i + 1, 2 * j] = -(inv @ k)[i, j]
            a[2 * i + 1, 2 * j + 1] = -(inv @ d)[i, j]
        bvec[2 * i + 1, 0] = (inv @ bq)[i]
    return a, bvec


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("integrator", ["euler", "rk4"])
def test_linearisation_at_the_upright(name, integrator):
    info = B.plant_info(name)
    n = len(info["state"])
    model = B.model_default(name, integrator=integrator, dt=0.01)
    a, b = upright_linearisation(name, model, info)
    if integrator == "rk4":
        ad, bd = rk4_discrete(a, b, 0.01)
    else:
        ad, bd = np.eye(n) + 0.01 * a, 0.01 * b
    delta = 1e-6
    fd_a = np.zeros((n, n))
    for j in range(n):
        e = np.zeros(B.MAX_STATE)
        e[j] = delta
        fd_a[:, j] = ((c_step(model, e, 0.0) - c_step(model, -e, 0.0)) / (2 * delta))[:n]
    fd_b = ((c_step(model, np.zeros(B.MAX_STATE), delta) - c_step(model, np.zeros(B.MAX_STATE), -delta))
            / (2 * delta))[:n]
    assert np.allclose(fd_a, ad, rtol=0, atol=1e-7 * np.max(np.abs(ad))), (fd_a - ad)
    assert np.allclose(fd_b, bd[:, 0], rtol=0, atol=1e-7 * np.max(np.abs(bd))), (fd_b, bd[:, 0])
    # the upright is unstable: A has an eigenvalue with a positive real part
    assert np.max(np.linalg.eigvals(a).real) > 1.0


def test_bad_state_gets_a_named_status():
    model = B.model_default("double_cart_pole")
    state = np.zeros(B.MAX_STATE)
    state[3] = np.nan
    status = B.lib.icoac_sim_model_step(ctypes.byref(model), state, 0.0)
    assert status == B.SIM_ERR_NONFINITE
    with pytest.raises(B.IcoacError, match="not finite"):
        B.check_status(status)
    assert np.isnan(state[3]) and np.all(state[[0, 1, 2, 4, 5]] == 0)


@pytest.mark.parametrize("name", NAMES)
def test_plant_grid(name):
    info = B.plant_info(name)
    n = info["rows"]["count"] * info["cols"]["count"]
    cells = np.zeros(n, dtype=B.CELL_DTYPE)
    B.check_status(B.lib.icoac_sim_plant_grid(info["index"], cells, n, 5))
    to_si = lambda w, i: (w["first"] + w["step"] * i) * (np.pi / 180 if w["degrees"] else 1.0)  # noqa: E731
    rows = np.arange(n) // info["cols"]["count"]
    cols = np.arange(n) % info["cols"]["count"]
    assert np.allclose(cells["theta0"], to_si(info["rows"], rows), rtol=0, atol=1e-12)
    assert np.allclose(cells["x0"], to_si(info["cols"], cols), rtol=0, atol=1e-12)
