// Build-time tool: URDF + plant file -> the robot part of a MuJoCo 2.2 scene (MJCF), meant to be
// <include>d by a hand-written wrapper scene (robots/walker3/scene.xml: floor, light, camera).
//
// The URDF is compiled by MuJoCo's own URDF reader (floating base via a world link + floating
// joint, fusestatic="false" so that sensor and sole frames stay bodies, no inertia from geometry,
// inertias as written), and the compiled model is written back as MJCF with %.17g numbers
// (mj_saveLastXML would round them to 6 digits). Kinematics and inertias therefore come only from
// the URDF. Added here: joint friction, damping and armature from the plant file, one torque motor
// per joint (gear 1, ctrlrange = URDF effort), sites and sensors (IMU, 6-axis F/T, encoders), and
// the URDF's <visual> shapes as drawn-only geoms (no contact, no mass).
//
// Sole plates: each foot's collision geometry is moved (same world placement) into the massless
// sole body, and the F/T site is put in that body at the F/T frame. MuJoCo's force/torque sensors
// read the wrench of the parent on the subtree of the site's body; with a massless subtree that
// holds only the sole plate, this is exactly minus the contact wrench, as a real sensor between
// ankle and sole plate would measure it (docs/simulation.md).
#include <mujoco/mujoco.h>
#include <urdf_parser/urdf_parser.h>

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "plant_config.hpp"

namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// MuJoCo reads URDF with its own defaults; give it ours (one <mujoco> element only) and a
// floating base: a world link plus a `floating` joint, which MuJoCo turns into a free joint.
std::string prepareUrdf(const std::string& urdf, const std::string& root_link) {
  if (urdf.find("<mujoco") != std::string::npos) {
    throw std::runtime_error("the URDF has its own <mujoco> element; remove it (the generator sets the compiler)");
  }
  const std::size_t robot = urdf.find("<robot");
  if (robot == std::string::npos) throw std::runtime_error("not a URDF: no <robot> element");
  const std::size_t at = urdf.find('>', robot) + 1;
  std::string extra =
      "\n<mujoco><compiler fusestatic=\"false\" inertiafromgeom=\"false\" balanceinertia=\"false\""
      " discardvisual=\"true\" strippath=\"false\"/></mujoco>\n";
  if (root_link != "world") {
    extra += "<link name=\"world\"/>\n<joint name=\"floating_base\" type=\"floating\"><parent link=\"world\"/>"
             "<child link=\"" + root_link + "\"/><origin xyz=\"0 0 0\" rpy=\"0 0 0\"/></joint>\n";
  }
  std::string out = urdf;
  out.insert(at, extra);
  return out;
}

mjModel* compileUrdf(const std::string& text) {
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const char* name = "hqp_scene_source.urdf";
  if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(text.size())) != 0) {
    throw std::runtime_error("mj_makeEmptyFileVFS failed");
  }
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), name)], text.data(), text.size());
  char error[1024] = {0};
  mjModel* m = mj_loadXML(name, vfs.get(), error, sizeof(error));
  mj_deleteVFS(vfs.get());
  if (!m) throw std::runtime_error(std::string("MuJoCo cannot compile the URDF: ") + error);
  return m;
}

std::string num(double x) {
  char b[40];
  std::snprintf(b, sizeof(b), "%.17g", x);
  return b;
}

// Drawn-only shapes need no round trip: 6 digits.
std::string shortNum(double x) {
  char b[40];
  std::snprintf(b, sizeof(b), "%.6g", x);
  return b;
}

std::string nums(const double* x, int n) {
  std::string s;
  for (int i = 0; i < n; ++i) s += (i ? " " : "") + num(x[i]);
  return s;
}

std::string name(const mjModel* m, mjtObj type, int id) {
  const char* n = mj_id2name(m, type, id);
  return n ? n : "";
}

// Pose of a world pose (p, q) relative to the world pose (pb, qb): pos and quat in b's frame.
void relativePose(const double* pb, const double* qb, const double* p, const double* q, double* pos,
                  double* quat) {
  double d[3] = {p[0] - pb[0], p[1] - pb[1], p[2] - pb[2]};
  double qb_inv[4];
  mju_negQuat(qb_inv, qb);
  mju_rotVecQuat(pos, d, qb_inv);
  mju_mulQuat(quat, qb_inv, q);
  mju_normalize4(quat);
  // Differences of world poses carry ~1e-16 noise; 1e-12 m / rad is far below any modelling detail.
  for (int i = 0; i < 3; ++i) pos[i] = std::round(pos[i] * 1e12) / 1e12;
  for (int i = 0; i < 4; ++i) quat[i] = std::round(quat[i] * 1e12) / 1e12;
}

struct Writer {
  const mjModel* m;
  mjData* d;
  const hqp::sim::PlantConfig& plant;
  const urdf::ModelInterface& urdf_model;
  std::set<int> foot_bodies;  // their geoms move into the sole bodies
  std::ostringstream out;

  void geom(int g, const double* pos, const double* quat, const std::string& ind, const std::string& geom_name) {
    std::string type, size;
    switch (m->geom_type[g]) {
      case mjGEOM_BOX: type = "box"; size = nums(m->geom_size + 3 * g, 3); break;
      case mjGEOM_CYLINDER: type = "cylinder"; size = nums(m->geom_size + 3 * g, 2); break;
      case mjGEOM_SPHERE: type = "sphere"; size = nums(m->geom_size + 3 * g, 1); break;
      case mjGEOM_CAPSULE: type = "capsule"; size = nums(m->geom_size + 3 * g, 2); break;
      default: throw std::runtime_error("unsupported collision geometry type in the URDF (use box, cylinder, sphere)");
    }
    out << ind << "<geom name=\"" << geom_name << "\" type=\"" << type << "\" size=\"" << size << "\" pos=\""
        << nums(pos, 3) << "\" quat=\"" << nums(quat, 4) << "\"/>\n";
  }

  // The link's URDF <visual> shapes as drawn-only geoms: no contact (contype/conaffinity 0) and
  // mass 0, so that the plant stays what <inertial> and <collision> say (inertiafromgeom is off
  // as well). MuJoCo's reader drops them (discardvisual), so they are read here with urdfdom.
  void visuals(const std::string& link_name, const std::string& ind) {
    const urdf::LinkConstSharedPtr link = urdf_model.getLink(link_name);
    if (!link) return;
    int k = 0;
    for (const urdf::VisualSharedPtr& v : link->visual_array) {
      if (!v || !v->geometry) continue;
      std::string type, size;
      switch (v->geometry->type) {
        case urdf::Geometry::BOX: {
          const auto& b = static_cast<const urdf::Box&>(*v->geometry).dim;
          type = "box";
          size = shortNum(0.5 * b.x) + " " + shortNum(0.5 * b.y) + " " + shortNum(0.5 * b.z);
          break;
        }
        case urdf::Geometry::CYLINDER: {
          const auto& c = static_cast<const urdf::Cylinder&>(*v->geometry);
          type = "cylinder";
          size = shortNum(c.radius) + " " + shortNum(0.5 * c.length);
          break;
        }
        case urdf::Geometry::SPHERE:
          type = "sphere";
          size = shortNum(static_cast<const urdf::Sphere&>(*v->geometry).radius);
          break;
        default: throw std::runtime_error("link " + link_name + ": unsupported visual geometry (use box, cylinder, sphere)");
      }
      // MuJoCo's URDF bodies sit at the link frames, so the URDF origin is the geom pose as is.
      const urdf::Pose& p = v->origin;
      urdf::Color c;
      c.r = c.g = c.b = 0.5f;
      if (v->material) c = v->material->color;
      out << ind << "<geom name=\"" << link_name << "_visual" << k++ << "\" type=\"" << type << "\" size=\"" << size
          << "\" pos=\"" << shortNum(p.position.x) << " " << shortNum(p.position.y) << " " << shortNum(p.position.z)
          << "\" quat=\"" << shortNum(p.rotation.w) << " " << shortNum(p.rotation.x) << " " << shortNum(p.rotation.y)
          << " " << shortNum(p.rotation.z) << "\" contype=\"0\" conaffinity=\"0\" group=\"1\" mass=\"0\" rgba=\""
          << shortNum(c.r) << " " << shortNum(c.g) << " " << shortNum(c.b) << " " << shortNum(c.a) << "\"/>\n";
    }
  }

  void joint(int j, const std::string& ind) {
    const std::string jn = name(m, mjOBJ_JOINT, j);
    if (m->jnt_type[j] == mjJNT_FREE) {
      out << ind << "<freejoint name=\"" << jn << "\"/>\n";
      return;
    }
    if (m->jnt_type[j] != mjJNT_HINGE) throw std::runtime_error("joint " + jn + ": only revolute joints are supported");
    const hqp::sim::JointPlant& p = plant.joint(jn);
    out << ind << "<joint name=\"" << jn << "\" type=\"hinge\" pos=\"" << nums(m->jnt_pos + 3 * j, 3)
        << "\" axis=\"" << nums(m->jnt_axis + 3 * j, 3) << "\"";
    if (m->jnt_limited[j]) out << " range=\"" << nums(m->jnt_range + 2 * j, 2) << "\"";
    out << " damping=\"" << num(p.viscous) << "\" frictionloss=\"" << num(p.coulomb) << "\" armature=\""
        << num(p.armature) << "\" solreffriction=\"" << nums(plant.solreffriction.data(), 2)
        << "\" solimpfriction=\"" << nums(plant.solimpfriction.data(), 5) << "\"/>\n";
  }

  void body(int b, int depth) {
    const std::string ind(2 * depth, ' '), in2(2 * depth + 2, ' ');
    const std::string bn = name(m, mjOBJ_BODY, b);
    out << ind << "<body name=\"" << bn << "\" pos=\"" << nums(m->body_pos + 3 * b, 3) << "\" quat=\""
        << nums(m->body_quat + 4 * b, 4) << "\">\n";
    if (m->body_mass[b] > 0) {
      out << in2 << "<inertial pos=\"" << nums(m->body_ipos + 3 * b, 3) << "\" quat=\""
          << nums(m->body_iquat + 4 * b, 4) << "\" mass=\"" << num(m->body_mass[b]) << "\" diaginertia=\""
          << nums(m->body_inertia + 3 * b, 3) << "\"/>\n";
    }
    for (int j = m->body_jntadr[b]; j >= 0 && j < m->body_jntadr[b] + m->body_jntnum[b]; ++j) joint(j, in2);
    if (!foot_bodies.count(b)) {
      for (int g = m->body_geomadr[b], k = 0; g >= 0 && g < m->body_geomadr[b] + m->body_geomnum[b]; ++g, ++k) {
        geom(g, m->geom_pos + 3 * g, m->geom_quat + 4 * g, in2, bn + "_geom" + std::to_string(k));
      }
    }
    visuals(bn, in2);
    if (bn == plant.imu_link) out << in2 << "<site name=\"imu\" pos=\"0 0 0\" size=\"0.01\"/>\n";
    for (const auto& ft : plant.force_torque) {
      if (bn != ft.sole) continue;
      // The sole plate: the foot's collision geometry, same world placement, in this body.
      const int foot = mj_name2id(m, mjOBJ_BODY, ft.foot.c_str());
      const int frame = mj_name2id(m, mjOBJ_BODY, ft.frame.c_str());
      if (foot < 0 || frame < 0) throw std::runtime_error("plant file: unknown link " + ft.foot + " or " + ft.frame);
      for (int g = m->body_geomadr[foot], k = 0; g >= 0 && g < m->body_geomadr[foot] + m->body_geomnum[foot]; ++g, ++k) {
        double gq[4], pos[3], quat[4];
        mju_mat2Quat(gq, d->geom_xmat + 9 * g);
        relativePose(d->xpos + 3 * b, d->xquat + 4 * b, d->geom_xpos + 3 * g, gq, pos, quat);
        geom(g, pos, quat, in2, bn + "_plate" + std::to_string(k));
      }
      double pos[3], quat[4];
      relativePose(d->xpos + 3 * b, d->xquat + 4 * b, d->xpos + 3 * frame, d->xquat + 4 * frame, pos, quat);
      out << in2 << "<site name=\"" << ft.name << "\" pos=\"" << nums(pos, 3) << "\" quat=\"" << nums(quat, 4)
          << "\" size=\"0.01\"/>\n";
      out << in2 << "<site name=\"" << bn << "\" pos=\"0 0 0\" size=\"0.005\"/>\n";
    }
    for (int c = 1; c < m->nbody; ++c) {
      if (m->body_parentid[c] == b) body(c, depth + 1);
    }
    out << ind << "</body>\n";
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"URDF + plant file -> MuJoCo MJCF of the robot (bodies, motors, sensors) for a scene <include>"};
  std::string urdf_path, plant_path, out_path;
  app.add_option("urdf", urdf_path, "robot URDF")->required()->check(CLI::ExistingFile);
  app.add_option("--plant", plant_path, "plant parameter file (YAML)")->required()->check(CLI::ExistingFile);
  app.add_option("-o,--output", out_path, "MJCF file to write")->required();
  CLI11_PARSE(app, argc, argv);

  try {
    const std::string urdf_text = readFile(urdf_path);
    const urdf::ModelInterfaceSharedPtr urdf_model = urdf::parseURDF(urdf_text);
    if (!urdf_model) throw std::runtime_error("urdfdom cannot parse " + urdf_path);
    const hqp::sim::PlantConfig plant = hqp::sim::loadPlantConfig(plant_path);

    mjModel* m = compileUrdf(prepareUrdf(urdf_text, urdf_model->getRoot()->name));
    mjData* d = mj_makeData(m);
    mj_kinematics(m, d);  // qpos0: every world pose at the URDF's zero configuration

    Writer w{m, d, plant, *urdf_model, {}, {}};
    for (const auto& ft : plant.force_torque) {
      const int foot = mj_name2id(m, mjOBJ_BODY, ft.foot.c_str());
      if (foot < 0 || mj_name2id(m, mjOBJ_BODY, ft.sole.c_str()) < 0) {
        throw std::runtime_error("plant file: unknown foot/sole link for sensor " + ft.name);
      }
      w.foot_bodies.insert(foot);
    }
    if (mj_name2id(m, mjOBJ_BODY, plant.imu_link.c_str()) < 0) {
      throw std::runtime_error("plant file: unknown IMU link " + plant.imu_link);
    }

    w.out << "<!-- Generated by hqp_urdf_to_mjcf from " << urdf_model->getName()
          << " URDF and the plant file. Do not edit: edit the URDF or the plant file. -->\n"
          << "<mujoco model=\"" << urdf_model->getName() << "\">\n"
          << "  <compiler angle=\"radian\" autolimits=\"true\" inertiafromgeom=\"false\"/>\n"
          << "  <worldbody>\n";
    for (int b = 1; b < m->nbody; ++b) {
      if (m->body_parentid[b] == 0) w.body(b, 2);
    }
    w.out << "  </worldbody>\n  <actuator>\n";
    std::vector<std::string> joints;
    for (int j = 0; j < m->njnt; ++j) {
      if (m->jnt_type[j] != mjJNT_HINGE) continue;
      const std::string jn = name(m, mjOBJ_JOINT, j);
      joints.push_back(jn);
      const auto uj = urdf_model->getJoint(jn);
      w.out << "    <motor name=\"" << jn << "\" joint=\"" << jn << "\" gear=\"1\"";
      if (uj && uj->limits && uj->limits->effort > 0) {
        w.out << " ctrlrange=\"" << num(-uj->limits->effort) << " " << num(uj->limits->effort) << "\"";
      }
      w.out << "/>\n";
    }
    w.out << "  </actuator>\n  <sensor>\n"
          << "    <framequat name=\"imu_quat\" objtype=\"site\" objname=\"imu\"/>\n"
          << "    <gyro name=\"imu_gyro\" site=\"imu\"/>\n"
          << "    <accelerometer name=\"imu_accel\" site=\"imu\"/>\n";
    for (const auto& ft : plant.force_torque) {
      w.out << "    <force name=\"" << ft.name << "_force\" site=\"" << ft.name << "\"/>\n"
            << "    <torque name=\"" << ft.name << "_torque\" site=\"" << ft.name << "\"/>\n";
    }
    for (const auto& jn : joints) {
      w.out << "    <jointpos name=\"" << jn << "_pos\" joint=\"" << jn << "\"/>\n"
            << "    <jointvel name=\"" << jn << "_vel\" joint=\"" << jn << "\"/>\n";
    }
    w.out << "  </sensor>\n</mujoco>\n";
    mj_deleteData(d);
    mj_deleteModel(m);

    std::ofstream f(out_path);
    f << w.out.str();
    if (!f) throw std::runtime_error("cannot write " + out_path);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hqp_urdf_to_mjcf: %s\n", e.what());
    return 1;
  }
  return 0;
}
