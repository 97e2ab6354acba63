"""The residual model from Python: simulator + GP mean is its step, and it predicts held-out real data
better than the simulator alone."""

import numpy as np
import pytest

import gpilqg
from conftest import cli


@pytest.fixture(scope="module")
def real_data(tmp_path_factory):
    """The real cart-pole (pole 1.3 m), 8 episodes of random excitation at 0.02 s."""
    path = tmp_path_factory.mktemp("residual") / "real.h5"
    status, _, err = cli("simulate", "--system", "cartpole", "--preset", "real", "--episodes", "8", "--steps", "120",
                         "--actuator-noise", "0.02", "--observation-noise", "0.0005", "--seed", "5", "--out", path)
    assert status == 0, err
    return gpilqg.read_measurements(path, "cartpole")


def transitions(episodes):
    x = np.vstack([e.x[:-1] for e in episodes])
    u = np.vstack([e.u[:-1] for e in episodes])
    x_next = np.vstack([e.x[1:] for e in episodes])
    return x, u, x_next


def test_the_step_is_the_simulator_plus_the_gp_mean_and_beats_the_simulator(real_data):
    simulator = gpilqg.StepModel("cartpole", dt=0.02, integrator="rk4", substeps=10)
    train = gpilqg.MeasurementSet("cartpole", [(e.t, e.x, e.u) for e in real_data.episodes[:6]])
    model = gpilqg.ResidualModel.fit(simulator, train, exact_points=300, restarts=0, max_evaluations=80)
    assert len(model.hyperparameters) == 4 and model.hyperparameters[0].shape == (7,)
    x, u, x_next = transitions(real_data.episodes[6:])
    mean, std = model.predict(x, u)
    assert mean.shape == std.shape == (len(x), 4) and (std > 0).all()
    for i in range(0, len(x), 25):
        np.testing.assert_allclose(model.step(x[i], u[i]), simulator.step(x[i], u[i]) + mean[i], rtol=1e-12, atol=1e-12)
    simulator_error = np.array([x_next[i] - simulator.step(x[i], u[i]) for i in range(len(x))])
    model_error = np.array([x_next[i] - model.step(x[i], u[i]) for i in range(len(x))])
    # On held-out episodes the GP removes most of the simulator's one-step error (the longer pole).
    assert np.linalg.norm(model_error) < 0.3 * np.linalg.norm(simulator_error)
    with pytest.raises(gpilqg.InputError, match="expected"):
        model.predict(x[:, :3], u)


def test_the_sensors_noise_sets_each_gps_lowest_noise_std(real_data):
    """With observation_std every output's fitted noise std is at least what two measurements of a step
    carry, sqrt(sigma_i^2 + sum_j A_ij^2 sigma_j^2), about sigma_i sqrt(2) since A is close to I over one
    0.02 s step (no process noise in this simulator)."""
    simulator = gpilqg.StepModel("cartpole", dt=0.02, integrator="rk4", substeps=10)
    train = gpilqg.MeasurementSet("cartpole", [(e.t, e.x, e.u) for e in real_data.episodes[:3]])
    sensors = np.full(4, 0.01)  # 20 times the data's 0.0005: the floor must bind
    model = gpilqg.ResidualModel.fit(simulator, train, exact_points=150, restarts=0, max_evaluations=40,
                                     observation_std=sensors)
    noise_std = np.exp([h[-1] for h in model.hyperparameters])
    assert (noise_std >= 0.01 * np.sqrt(2) * 0.99).all(), noise_std
    with pytest.raises(gpilqg.InputError, match="observation_std"):
        gpilqg.ResidualModel.fit(simulator, train, observation_std=np.full(3, 0.01))
