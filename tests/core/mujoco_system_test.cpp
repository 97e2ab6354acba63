// MuJoCo models as systems (mujoco_system.hpp): names, the model's own integrator, Jacobians from
// mjd_transitionFD against central differences of mj_step, effects inside the step against a
// hand-written mj_step loop, parameter overrides, thread safety and the errors of
// docs/formats.md#systems-and-their-names.

#include <fstream>
#include <map>
#include <thread>

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include "gpilqg/core/effect_library.hpp"
#include "gpilqg/core/integrator.hpp"
#include "gpilqg/core/mujoco_system.hpp"
#include "gpilqg/core/system_registry.hpp"
#include "test_support.hpp"

namespace gpilqg {
namespace {

std::string arm_path() { return (test::source_dir() / "data" / "two_link_arm.xml").string(); }

/// A hand-written rollout of the file with MuJoCo's C API: `substeps` calls of mj_step from x under
/// ctrl = u, with qfrc_applied = force(qpos, qvel) set before each call.
Vector reference_step(const Vector& x, const Vector& u, int substeps,
                      const std::function<Vector(const Vector&)>& force = nullptr) {
  char error[512] = "";
  mjModel* m = mj_loadXML(arm_path().c_str(), nullptr, error, sizeof error);
  EXPECT_NE(m, nullptr) << error;
  mjData* d = mj_makeData(m);
  for (int i = 0; i < m->nv; ++i) {
    d->qpos[i] = x(i);
    d->qvel[i] = x(m->nv + i);
  }
  for (int a = 0; a < m->nu; ++a) d->ctrl[a] = u(a);
  for (int s = 0; s < substeps; ++s) {
    if (force) {
      Vector state(2 * m->nv);
      for (int i = 0; i < m->nv; ++i) {
        state(i) = d->qpos[i];
        state(m->nv + i) = d->qvel[i];
      }
      const Vector Q = force(state);
      for (int i = 0; i < m->nv; ++i) d->qfrc_applied[i] = Q(i);
    }
    mj_step(m, d);
  }
  Vector out(2 * m->nv);
  for (int i = 0; i < m->nv; ++i) {
    out(i) = d->qpos[i];
    out(m->nv + i) = d->qvel[i];
  }
  mj_deleteData(d);
  mj_deleteModel(m);
  return out;
}

TEST(MujocoSystem, NamesStatesAndControlsFollowTheModel) {
  const auto arm = MujocoSystem::load(arm_path());
  EXPECT_EQ(arm->name(), "two_link_arm");
  EXPECT_EQ(names_of(arm->states()), (std::vector<std::string>{"shoulder", "elbow", "shoulder_dot", "elbow_dot"}));
  EXPECT_EQ(names_of(arm->controls()), (std::vector<std::string>{"shoulder_motor", "elbow_motor"}));
  EXPECT_EQ(arm->states()[0].unit, "rad");
  EXPECT_EQ(arm->states()[2].unit, "rad/s");
  EXPECT_DOUBLE_EQ(arm->timestep(), 0.01);
  EXPECT_EQ(system_signature(arm_path()).name, "two_link_arm");
}

TEST(MujocoSystem, StepIsTheModelsOwnIntegratorOverWholeTimesteps) {
  const auto arm = MujocoSystem::load(arm_path());
  const auto model = make_step_model(arm, Integrator::RK4, 0.05);  // RK4 is not used: the model's Euler is
  const Vector x = (Vector(4) << 0.4, -0.3, 0.7, -1.1).finished();
  const Vector u = (Vector(2) << 0.8, -0.5).finished();
  EXPECT_MATRIX_NEAR(model->next(x, u), reference_step(x, u, 5), 0.0);
}

TEST(MujocoSystem, TransitionJacobiansMatchCentralDifferencesOfMjStep) {
  const auto arm = MujocoSystem::load(arm_path());
  for (const double dt : {0.01, 0.05}) {
    const auto model = make_step_model(arm, Integrator::Euler, dt);
    const Vector x = (Vector(4) << 0.9, 1.2, -0.4, 2.0).finished();
    const Vector u = (Vector(2) << 1.5, -0.7).finished();
    StepJacobians J;
    Vector next(4);
    model->step(x, u, next, &J);
    const int substeps = static_cast<int>(std::lround(dt / 0.01));
    const Matrix A = test::numeric_jacobian([&](const Vector& xs) { return reference_step(xs, u, substeps); }, x, 1e-6);
    const Matrix B = test::numeric_jacobian([&](const Vector& us) { return reference_step(x, us, substeps); }, u, 1e-6);
    EXPECT_TRUE(test::matrices_near(J.A, A, 1e-6, 1e-6)) << "dt = " << dt;
    EXPECT_TRUE(test::matrices_near(J.B, B, 1e-6, 1e-6)) << "dt = " << dt;
  }
}

TEST(MujocoSystem, ForceEffectsEnterEverySubstepWithTheirStateDerivatives) {
  // Coulomb friction on the elbow and a constant horizontal force at the forearm's centre of mass.
  ModelSpec spec;
  spec.system = arm_path();
  spec = spec.with(find_effect(arm_path(), "joint_coulomb_friction:elbow"), Vector::Constant(1, 0.3));
  spec = spec.with(find_effect(arm_path(), "external_force_x:forearm"), Vector::Constant(1, 2.0));
  const auto model = make_step_model(spec.build(), Integrator::Euler, 0.03);
  const Vector x = (Vector(4) << 0.3, 0.5, -0.2, 0.04).finished();
  const Vector u = (Vector(2) << 0.2, 0.1).finished();

  // The reference applies the same forces through qfrc_applied: -tau tanh(qdot / 0.05) on the elbow,
  // and J_com' F e_x with the forearm's centre at (l1 sin q1 + c2 sin(q1 + q2), ...) along x.
  const auto forces = [](const Vector& s) {
    Vector Q = Vector::Zero(2);
    Q(1) = -0.3 * std::tanh(s(3) / 0.05);
    // The forearm's centre hangs at x = -(l1 sin q1 + c2 sin(q1 + q2)) (hinges about +y, the chain
    // along -z at q = 0; data/two_link_arm.xml), so J_com' e_x = dx/dq.
    const double F = 2.0, l1 = 0.5, c2 = 0.2;
    Q(0) = F * -(l1 * std::cos(s(0)) + c2 * std::cos(s(0) + s(1)));
    Q(1) += F * -(c2 * std::cos(s(0) + s(1)));
    return Q;
  };
  StepJacobians J;
  Vector next(4);
  model->step(x, u, next, &J);
  EXPECT_TRUE(test::matrices_near(next, reference_step(x, u, 3, forces), 1e-12, 1e-10));
  const Matrix A = test::numeric_jacobian([&](const Vector& xs) { return reference_step(xs, u, 3, forces); }, x, 1e-6);
  EXPECT_TRUE(test::matrices_near(J.A, A, 1e-5, 1e-5));
}

TEST(MujocoSystem, ParameterOverridesChangeTheModelsFields) {
  const auto arm = MujocoSystem::load(arm_path());
  auto find = [](const std::vector<Parameter>& ps, const std::string& name) {
    for (const auto& p : ps)
      if (p.name == name) return p.value;
    ADD_FAILURE() << "no parameter " << name;
    return 0.0;
  };
  EXPECT_DOUBLE_EQ(find(arm->parameters(), "forearm.mass"), 0.6);
  EXPECT_DOUBLE_EQ(find(arm->parameters(), "elbow.damping"), 0.05);
  const auto heavier = arm->with_parameters({{"forearm.mass", 0.9}, {"elbow_motor.gear", 2.0}});
  EXPECT_DOUBLE_EQ(find(heavier->parameters(), "forearm.mass"), 0.9);
  EXPECT_DOUBLE_EQ(find(heavier->parameters(), "elbow_motor.gear"), 2.0);
  EXPECT_DOUBLE_EQ(find(arm->parameters(), "forearm.mass"), 0.6);  // the original is unchanged
  // Doubling the gear doubles the torque: the elbow's acceleration response to its motor doubles.
  const Vector x = Vector::Zero(4);
  const Vector u = (Vector(2) << 0.0, 1.0).finished();
  const auto geared = arm->with_parameters({{"elbow_motor.gear", 2.0}});
  const Vector a1 = arm->f(x, u) - arm->f(x, Vector::Zero(2));
  const Vector a2 = geared->f(x, u) - geared->f(x, Vector::Zero(2));
  EXPECT_TRUE(test::matrices_near(a2, 2.0 * a1, 1e-12, 1e-9));
  EXPECT_THROW(arm->with_parameters({{"forearm.weight", 1.0}}), std::invalid_argument);
  EXPECT_THROW(arm->with_parameters({{"forearm.mass", -1.0}}), std::invalid_argument);
}

TEST(MujocoSystem, GeneralisedForceMapIsTheInverseMassMatrix) {
  // xdot gains W Q: compare f with qfrc_applied = Q (by an effect) against f + W Q.
  const auto arm = MujocoSystem::load(arm_path());
  const Vector x = (Vector(4) << 0.7, -0.4, 0.3, 0.1).finished();
  const Vector u = Vector::Zero(2);
  Matrix W;
  std::vector<Matrix> dW;
  arm->generalised_force_map(x, W, &dW);
  const Vector Q = (Vector(2) << 0.3, -0.2).finished();
  // W Q against the change of qacc when a torque Q is commanded through the unit-gear motors.
  const Vector by_motors = arm->f(x, Q) - arm->f(x, u);
  EXPECT_TRUE(test::matrices_near(W * Q, by_motors, 1e-10, 1e-8));
  const Matrix dW0 = test::numeric_jacobian(
      [&](const Vector& xs) {
        Matrix Ws;
        arm->generalised_force_map(xs, Ws, nullptr);
        return Vector(Eigen::Map<const Vector>(Ws.data(), Ws.size()));
      },
      x, 1e-5);
  EXPECT_TRUE(test::matrices_near(Eigen::Map<const Vector>(dW[0].data(), dW[0].size()), dW0.col(0), 1e-6, 1e-5));
}

TEST(MujocoSystem, ProcessNoiseColumnsAreTheInputMatrixScaled) {
  // Additive actuator noise: column j is sigma_j b_j with b = df/du; for unit-gear motors b_j is
  // column j of W = [0; M^-1] (noise.hpp), and the step model hands the columns through.
  auto arm = MujocoSystem::load(arm_path());
  ActuatorNoise noise;
  noise.additive_std = (Vector(2) << 0.3, 0.7).finished();
  arm->set_noise_model(noise);
  const auto model = make_step_model(arm, Integrator::Euler, 0.05);
  const Vector x = (Vector(4) << 0.5, -0.2, 0.1, 0.3).finished();
  const Vector u = Vector::Zero(2);
  DiffusionColumns columns;
  const auto workspace = model->make_workspace();
  model->noise(x, u, columns, true, *workspace);
  ASSERT_EQ(columns.count(), 2);
  Matrix W;
  arm->generalised_force_map(x, W, nullptr);
  EXPECT_TRUE(test::matrices_near(columns.columns.col(0), 0.3 * W.col(0), 1e-8, 1e-6));
  EXPECT_TRUE(test::matrices_near(columns.columns.col(1), 0.7 * W.col(1), 1e-8, 1e-6));
}

TEST(MujocoSystem, SeveralThreadsStepOneModel) {
  const auto model = make_step_model(MujocoSystem::load(arm_path()), Integrator::Euler, 0.05);
  const Vector u = (Vector(2) << 0.3, -0.2).finished();
  std::vector<Vector> serial(16), parallel(16);
  for (int i = 0; i < 16; ++i) serial[i] = model->next(Vector::Constant(4, 0.05 * i), u);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int i = t; i < 16; i += 4) {
        StepJacobians J;
        Vector next(4);
        model->step(Vector::Constant(4, 0.05 * i), u, next, &J);
        parallel[i] = next;
      }
    });
  for (auto& th : threads) th.join();
  for (int i = 0; i < 16; ++i) EXPECT_MATRIX_NEAR(parallel[i], serial[i], 0.0);
}

/// Writes `text` to a file in a fresh folder and returns its path.
std::string write_model(const std::string& label, const std::string& text) {
  const auto path = test::temporary_dir(label) / "model.xml";
  std::ofstream(path) << text;
  return path.string();
}

// A centre-of-mass override moves the body's inertial frame (body_ipos) and nothing else: the arm with
// forearm.com_x = 0.03 and forearm.com_z = -0.23 moves as the file whose forearm has
// <inertial pos="0.03 0 -0.23"> with the same mass and inertia about its centre.
TEST(MujocoSystem, ACentreOfMassOverrideIsTheFileWithTheBodysInertialFrameMoved) {
  const auto arm = MujocoSystem::load(arm_path());
  double com_z = 1.0;
  for (const auto& p : arm->parameters())
    if (p.name == "forearm.com_z") com_z = p.value;
  EXPECT_DOUBLE_EQ(com_z, -0.2);
  const auto moved = arm->with_parameters({{"forearm.com_x", 0.03}, {"forearm.com_z", -0.23}});
  std::string text;
  {
    std::ifstream in(arm_path());
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::string from = R"(<inertial pos="0 0 -0.2" mass="0.6")";
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos);
  text.replace(at, from.size(), R"(<inertial pos="0.03 0 -0.23" mass="0.6")");
  const auto file = MujocoSystem::load(write_model("com_moved", text));
  for (const Vector& x : {Vector((Vector(4) << 0.7, -0.4, 0.3, 0.1).finished()),
                          Vector((Vector(4) << -1.2, 0.9, -0.5, 2.0).finished())}) {
    const Vector u = (Vector(2) << 0.4, -0.3).finished();
    EXPECT_TRUE(test::matrices_near(moved->f(x, u), file->f(x, u), 1e-12, 1e-12));
    EXPECT_FALSE(test::matrices_near(arm->f(x, u), file->f(x, u), 1e-3, 1e-3)) << "the shift changes the motion";
  }
}

// A body whose file puts its centre at the body's origin: MuJoCo's compiler marks its inertial frame as
// the body's own, a shortcut the override must undo. A bob on a hinge with its centre at the hinge
// swings under gravity once com_z = -0.1, as the file with <inertial pos="0 0 -0.1"> does.
TEST(MujocoSystem, ACentreOfMassOverrideMovesACentreTheFileHasAtTheBodysOrigin) {
  const auto model = [](const std::string& pos) {
    return "<mujoco><option gravity=\"0 0 -9.81\"/><worldbody><body name=\"bob\"><joint name=\"hinge\" "
           "type=\"hinge\" axis=\"0 1 0\"/><inertial pos=\"" + pos +
           "\" mass=\"1\" diaginertia=\"0.01 0.01 0.01\"/></body></worldbody></mujoco>";
  };
  const auto at_origin = MujocoSystem::load(write_model("com_at_origin", model("0 0 0")));
  const auto below = MujocoSystem::load(write_model("com_below", model("0 0 -0.1")));
  const auto moved = at_origin->with_parameters({{"bob.com_z", -0.1}});
  const Vector x = (Vector(2) << 0.4, 0.0).finished();
  const Vector u = Vector::Zero(0);
  EXPECT_NEAR(at_origin->f(x, u)(1), 0.0, 1e-12) << "no lever, no swing";
  EXPECT_TRUE(test::matrices_near(moved->f(x, u), below->f(x, u), 1e-12, 1e-12));
  EXPECT_LT(below->f(x, u)(1), -1.0);
}

// A second-moment override is the file with the moments of that spread: a bob on a hinge about y whose
// centre is at the hinge (MuJoCo's shortcut of a centre in the body's frame) and one 0.1 m below it,
// with moments (0.01, 0.02, 0.015), i.e. second moments S = (0.0125, 0.0025, 0.0075); S_1 = 0.0225
// makes the moments (0.01, 0.03, 0.025). A mass override scales the spreads the overrides do not give:
// mass 2 with S_1 = 0.0225 makes S = (0.0225, 0.005, 0.015), the moments (0.02, 0.0375, 0.0275). The
// hinge sees only I_2; the three spreads are read back.
TEST(MujocoSystem, ASecondMomentOverrideIsTheFileWithTheMomentsOfThatSpread) {
  const auto model = [](const std::string& pos, const std::string& mass, const std::string& moments) {
    return "<mujoco><option gravity=\"0 0 -9.81\"/><worldbody><body name=\"bob\"><joint name=\"hinge\" "
           "type=\"hinge\" axis=\"0 1 0\" damping=\"0.3\"/><inertial pos=\"" + pos + "\" mass=\"" + mass +
           "\" diaginertia=\"" + moments + "\"/></body></worldbody></mujoco>";
  };
  for (const std::string pos : {"0 0 0", "0 0 -0.1"}) {
    const auto file = MujocoSystem::load(write_model("moment_file", model(pos, "1", "0.01 0.02 0.015")));
    double s1 = 0.0;
    for (const auto& p : file->parameters())
      if (p.name == "bob.second_moment_1") s1 = p.value;
    EXPECT_NEAR(s1, 0.0125, 1e-15);
    const auto changed = MujocoSystem::load(write_model("moment_changed", model(pos, "1", "0.01 0.03 0.025")));
    const auto heavier = MujocoSystem::load(write_model("moment_heavier", model(pos, "2", "0.02 0.0375 0.0275")));
    const auto spread = file->with_parameters({{"bob.second_moment_1", 0.0225}});
    const auto both = file->with_parameters({{"bob.second_moment_1", 0.0225}, {"bob.mass", 2.0}});
    for (const Vector& x : {Vector((Vector(2) << 0.4, 1.5).finished()), Vector((Vector(2) << -1.1, -0.7).finished())}) {
      const Vector u = Vector::Zero(0);
      EXPECT_TRUE(test::matrices_near(spread->f(x, u), changed->f(x, u), 1e-12, 1e-12)) << pos;
      EXPECT_TRUE(test::matrices_near(both->f(x, u), heavier->f(x, u), 1e-12, 1e-12)) << pos;
      EXPECT_FALSE(test::matrices_near(file->f(x, u), changed->f(x, u), 1e-3, 1e-3)) << "the spread changes the motion";
    }
    std::map<std::string, double> read;
    for (const auto& p : both->parameters()) read[p.name] = p.value;
    EXPECT_NEAR(read["bob.second_moment_1"], 0.0225, 1e-15) << "as given";
    EXPECT_NEAR(read["bob.second_moment_2"], 0.005, 1e-15) << "scaled with the mass";
    EXPECT_NEAR(read["bob.second_moment_3"], 0.015, 1e-15) << "scaled with the mass";
  }
}

TEST(MujocoSystem, TheLibraryHasTheGenericEffectsWithAliases) {
  const auto& library = effect_library(arm_path());
  std::vector<std::string> names;
  for (const auto& e : library) names.push_back(e.name);
  for (const char* expected :
       {"joint_viscous_damping:shoulder", "joint_coulomb_friction:elbow", "actuator_gain:elbow_motor",
        "external_force_x:forearm", "external_force_z:upper_arm", "param:forearm.mass", "param:elbow.damping",
        "param:elbow.armature", "param:elbow.frictionloss", "param:shoulder.stiffness", "param:shoulder_motor.gear",
        "param:forearm.com_x", "param:upper_arm.com_z"})
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
  // A centre of mass moves by at most its body's length: for the forearm the larger of its centre's
  // 0.2 m from the elbow and its radius of gyration sqrt((0.008 + 0.008 + 0.0005) / 1.2) = 0.117 m.
  for (const auto& e : library)
    if (e.name == "param:forearm.com_x") {
      ASSERT_EQ(e.parameters.size(), 1u);
      EXPECT_DOUBLE_EQ(e.parameters[0].scale, 0.2);
      EXPECT_DOUBLE_EQ(e.parameters[0].lower, -0.2);
      EXPECT_DOUBLE_EQ(e.parameters[0].upper, 0.2);
      EXPECT_FALSE(e.parameters[0].strictly_positive);
    }
  // A second moment is >= 0 and grows by at most m L^2: the forearm's moments (0.008, 0.008, 0.0005)
  // kg m^2 are the spreads S = (0.00025, 0.00025, 0.00775), m L^2 = 0.6 * 0.2^2 = 0.024, and the
  // typical size is the mean spread, 0.0165 / 6 = 0.00275.
  int moments = 0;
  for (const auto& e : library)
    if (e.name == "param:forearm.second_moment_1" || e.name == "param:forearm.second_moment_3") {
      ++moments;
      const bool first = e.name.back() == '1';
      EXPECT_EQ(e.parameters[0].lower, 0.0);
      EXPECT_NEAR(e.parameters[0].upper, (first ? 0.00025 : 0.00775) + 0.024, 1e-15);
      EXPECT_NEAR(e.parameters[0].scale, 0.00275, 1e-15);
      EXPECT_TRUE(e.on_request) << "ranked only on request";
    }
  EXPECT_EQ(moments, 2);
  const auto entry = find_system(arm_path());
  bool damping_alias = false;
  for (const auto& group : entry->same_physics)
    damping_alias = damping_alias || (group == std::vector<std::string>{"param:elbow.damping", "joint_viscous_damping:elbow"});
  EXPECT_TRUE(damping_alias);
}

TEST(MujocoSystem, SprungJointsHaveACubicSpringCandidateAboutTheirRestPosition) {
  // A slide with a spring (stiffness 2, rest at 0.1) on a hinge without one: only the slide may
  // stiffen. Q_y = -k3 (y - 0.1)^3, checked against that closed form and its derivative against
  // central differences.
  const std::string path = write_model("cubic_spring", R"(<mujoco>
  <option gravity="0 0 0"/>
  <worldbody><body name="b"><joint name="y" type="slide" axis="1 0 0" stiffness="2" springref="0.1"/>
    <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
    <body name="c"><joint name="h" type="hinge" axis="0 1 0"/>
      <inertial pos="0 0 0.1" mass="1" diaginertia="1 1 1"/></body></body></worldbody>
</mujoco>)");
  const auto& library = effect_library(path);
  const auto named = [&](const std::string& name) {
    return std::find_if(library.begin(), library.end(), [&](const LibraryEffect& e) { return e.name == name; });
  };
  EXPECT_EQ(named("joint_cubic_spring:h"), library.end()) << "a hinge without a spring has no rest position";
  const auto cubic = named("joint_cubic_spring:y");
  ASSERT_NE(cubic, library.end());
  ASSERT_TRUE(cubic->force);
  EXPECT_EQ(cubic->parameters.at(0).unit, "N/m^3");
  const Vector theta = Vector::Constant(1, 3.0);
  const Vector u = Vector::Zero(0);
  const auto force = [&](const Vector& x) {
    Vector Q = Vector::Zero(2);
    cubic->force->add_force(x, u, theta, Q, nullptr, nullptr);
    return Q;
  };
  const Vector x = (Vector(4) << 0.4, 0.2, -0.3, 0.5).finished();
  EXPECT_NEAR(force(x)(0), -3.0 * std::pow(0.4 - 0.1, 3), 1e-14);
  EXPECT_EQ(force(x)(1), 0.0);
  Matrix dQ = Matrix::Zero(2, 4);
  Vector Q = Vector::Zero(2);
  cubic->force->add_force(x, u, theta, Q, &dQ, nullptr);
  EXPECT_TRUE(test::matrices_near(dQ, test::numeric_jacobian(force, x, 1e-6), 1e-7, 1e-7));
}

std::string load_error(const std::string& path) {
  try {
    MujocoSystem::load(path);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(MujocoSystem, BadModelsAreRefusedWithWhatIsWrong) {
  const std::string body_open = "<mujoco><worldbody><body name=\"b\">";
  const std::string body_close = "<geom size=\"0.1\" mass=\"1\"/></body></worldbody>";
  EXPECT_NE(load_error(write_model("mj_free", body_open + "<joint name=\"j\" type=\"free\"/>" + body_close +
                                                  "<actuator><motor name=\"m\" joint=\"j\"/></actuator></mujoco>"))
                .find("joint 0 ('j') is a free joint"),
            std::string::npos);
  EXPECT_NE(load_error(write_model("mj_ball", body_open + "<joint name=\"ball\" type=\"ball\"/>" + body_close +
                                                  "<actuator><motor name=\"m\" joint=\"ball\" gear=\"1 0 0\"/></actuator></mujoco>"))
                .find("'ball') is a ball joint"),
            std::string::npos);
  EXPECT_NE(load_error(write_model("mj_unnamed_joint", body_open + "<joint type=\"hinge\"/>" + body_close + "</mujoco>"))
                .find("joint 0 has no name"),
            std::string::npos);
  EXPECT_NE(load_error(write_model("mj_unnamed_actuator", body_open + "<joint name=\"j\" type=\"hinge\"/>" + body_close +
                                                              "<actuator><motor joint=\"j\"/></actuator></mujoco>"))
                .find("actuator 0 has no name"),
            std::string::npos);
  const std::string parse = load_error(write_model("mj_parse", "<mujoco>\n<worldbody>\n<body>\n<geom size=\"1\" bad=\"2\"/>\n"
                                                               "</body></worldbody></mujoco>\n"));
  EXPECT_NE(parse.find("model.xml: MuJoCo cannot load the model"), std::string::npos) << parse;
  EXPECT_NE(parse.find("line 4"), std::string::npos) << parse;
  const std::string hinge = "<joint name=\"j\" type=\"hinge\"/>" + body_close + "</mujoco>";
  const std::string zero = write_model("mj_timestep", "<mujoco><option timestep=\"0\"/><worldbody><body name=\"b\">" + hinge);
  EXPECT_EQ(load_error(zero), zero + ": <option timestep=\"0\">: the model's timestep is 0 s; expected a finite value > 0 "
                                     "(the length of one MuJoCo step)");
  EXPECT_NE(load_error("/nonexistent/model.xml").find("/nonexistent/model.xml: no such file; expected a MuJoCo model"), std::string::npos);
  const auto arm = MujocoSystem::load(arm_path());
  try {
    make_step_model(arm, Integrator::Euler, 0.025);
    ADD_FAILURE() << "dt = 0.025 with a 0.01 s timestep was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("not a whole multiple of the MuJoCo model's timestep 0.01"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace gpilqg
