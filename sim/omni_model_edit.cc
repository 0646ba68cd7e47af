#include "sim/omni_model_edit.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "sim/mujoco_util.h"

namespace vmh::sim {
namespace {

int find(const mjModel* m, mjtObj type, const char* name,
         const std::string& source) {
  const int id = mj_name2id(m, type, name);
  if (id < 0) {
    const char* what = type == mjOBJ_BODY     ? "body"
                       : type == mjOBJ_JOINT  ? "joint"
                       : type == mjOBJ_TENDON ? "tendon"
                                              : "actuator";
    throw SimError(source + ": no Omni " + what + " named '" + name +
                   "' (models/omni/omni.xml's names are expected)");
  }
  return id;
}

void check_scale(double v, const char* field) {
  if (!std::isfinite(v) || !(v > 0.0)) {
    throw std::invalid_argument(std::string("Omni model edit: ") + field +
                                " must be a finite number > 0, not " +
                                std::to_string(v));
  }
}

void set_const(mjModel* m) {
  mjData* d = mj_makeData(m);
  if (d == nullptr) throw SimError("Omni model edit: mj_makeData failed");
  mj_setConst(m, d);
  mj_deleteData(d);
}

}  // namespace

bool OmniModelEdit::is_identity() const {
  return mass_scale == 1.0 && damping_scale == 1.0 && friction_scale == 1.0 &&
         motor_gain == Vec3::Ones() && link1_scale == 1.0 &&
         link2_scale == 1.0 && !motor3_relative;
}

void apply_omni_edit(mjModel* m, const OmniModelEdit& e) {
  const std::string src = "the scene";
  check_scale(e.mass_scale, "mass_scale");
  check_scale(e.damping_scale, "damping_scale");
  check_scale(e.friction_scale, "friction_scale");
  check_scale(e.link1_scale, "link1_scale");
  check_scale(e.link2_scale, "link2_scale");
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(e.motor_gain[i]) || e.motor_gain[i] == 0.0) {
      throw std::invalid_argument("Omni model edit: motor_gain " +
                                  std::to_string(i + 1) +
                                  " must be finite and not zero");
    }
  }
  if (e.is_identity()) return;
  for (const char* name : kOmniBodies) {
    const int b = find(m, mjOBJ_BODY, name, src);
    m->body_mass[b] *= e.mass_scale;
    for (int k = 0; k < 3; ++k) m->body_inertia[3 * b + k] *= e.mass_scale;
  }
  for (const char* name : kOmniJoints) {
    const int dof = m->jnt_dofadr[find(m, mjOBJ_JOINT, name, src)];
    m->dof_damping[dof] *= e.damping_scale;
    m->dof_frictionloss[dof] *= e.friction_scale;
  }
  for (int i = 0; i < 3; ++i) {
    m->actuator_gear[6 * find(m, mjOBJ_ACTUATOR, kOmniMotors[i], src)] *=
        e.motor_gain[i];
  }
  const int forearm = find(m, mjOBJ_BODY, "forearm", src);
  const int wrist = find(m, mjOBJ_BODY, "gimbal_yaw", src);
  for (int k = 0; k < 3; ++k) {
    m->body_pos[3 * forearm + k] *= e.link1_scale;
    m->body_pos[3 * wrist + k] *= e.link2_scale;
  }
  if (e.motor3_relative) {
    const int t3 = find(m, mjOBJ_TENDON, "t3", src);
    const int q2 = find(m, mjOBJ_JOINT, "q2", src);
    bool found = false;
    for (int w = m->tendon_adr[t3]; w < m->tendon_adr[t3] + m->tendon_num[t3]; ++w) {
      if (m->wrap_type[w] == mjWRAP_JOINT && m->wrap_objid[w] == q2) {
        m->wrap_prm[w] = 0.0;
        found = true;
      }
    }
    if (!found) {
      throw SimError(src + ": tendon t3 does not couple q2; cannot make motor 3 relative");
    }
  }
  set_const(m);
}

std::string omni_edit_text(const OmniModelEdit& e) {
  if (e.is_identity()) return "none";
  std::ostringstream s;
  const char* sep = "";
  auto put = [&](const char* name, double v) {
    if (v == 1.0) return;
    s << sep << name << '=' << v;
    sep = ",";
  };
  put("mass_scale", e.mass_scale);
  put("damping_scale", e.damping_scale);
  put("friction_scale", e.friction_scale);
  for (int i = 0; i < 3; ++i) {
    const std::string n = "motor_gain" + std::to_string(i + 1);
    put(n.c_str(), e.motor_gain[i]);
  }
  put("link1_scale", e.link1_scale);
  put("link2_scale", e.link2_scale);
  if (e.motor3_relative) s << sep << "motor3_relative";
  return s.str();
}

void copy_omni_parameters(mjModel* dst, const mjModel* src,
                          const std::string& src_name) {
  const std::string dname = "the scene";
  for (const char* name : kOmniBodies) {
    const int a = find(dst, mjOBJ_BODY, name, dname);
    const int b = find(src, mjOBJ_BODY, name, src_name);
    dst->body_mass[a] = src->body_mass[b];
    for (int k = 0; k < 3; ++k) {
      dst->body_inertia[3 * a + k] = src->body_inertia[3 * b + k];
      dst->body_ipos[3 * a + k] = src->body_ipos[3 * b + k];
      dst->body_pos[3 * a + k] = src->body_pos[3 * b + k];
    }
    for (int k = 0; k < 4; ++k) {
      dst->body_iquat[4 * a + k] = src->body_iquat[4 * b + k];
      dst->body_quat[4 * a + k] = src->body_quat[4 * b + k];
    }
  }
  for (const char* name : kOmniJoints) {
    const int ja = find(dst, mjOBJ_JOINT, name, dname);
    const int jb = find(src, mjOBJ_JOINT, name, src_name);
    const int da = dst->jnt_dofadr[ja], db = src->jnt_dofadr[jb];
    dst->dof_damping[da] = src->dof_damping[db];
    dst->dof_frictionloss[da] = src->dof_frictionloss[db];
    dst->dof_armature[da] = src->dof_armature[db];
    dst->jnt_range[2 * ja] = src->jnt_range[2 * jb];
    dst->jnt_range[2 * ja + 1] = src->jnt_range[2 * jb + 1];
  }
  for (const char* name : kOmniMotors) {
    const int a = find(dst, mjOBJ_ACTUATOR, name, dname);
    const int b = find(src, mjOBJ_ACTUATOR, name, src_name);
    for (int k = 0; k < 6; ++k) {
      dst->actuator_gear[6 * a + k] = src->actuator_gear[6 * b + k];
    }
    for (int k = 0; k < 2; ++k) {
      dst->actuator_ctrlrange[2 * a + k] = src->actuator_ctrlrange[2 * b + k];
      dst->actuator_forcerange[2 * a + k] = src->actuator_forcerange[2 * b + k];
    }
  }
  for (const char* name : {"t1", "t2", "t3"}) {
    const int ta = find(dst, mjOBJ_TENDON, name, dname);
    const int tb = find(src, mjOBJ_TENDON, name, src_name);
    // the same joints in each (by name), their coefficients copied
    for (int wa = dst->tendon_adr[ta]; wa < dst->tendon_adr[ta] + dst->tendon_num[ta]; ++wa) {
      const char* jname = mj_id2name(dst, mjOBJ_JOINT, dst->wrap_objid[wa]);
      const int jb = jname ? mj_name2id(src, mjOBJ_JOINT, jname) : -1;
      double coef = 0.0;
      for (int wb = src->tendon_adr[tb]; wb < src->tendon_adr[tb] + src->tendon_num[tb]; ++wb) {
        if (src->wrap_objid[wb] == jb) coef = src->wrap_prm[wb];
      }
      dst->wrap_prm[wa] = coef;
    }
  }
  set_const(dst);
}

void load_omni_parameters(mjModel* dst, const std::string& omni_xml_path) {
  ModelPtr src = load_model(omni_xml_path);
  copy_omni_parameters(dst, src.get(), omni_xml_path);
}

ModelHook omni_model_hook(const std::string& omni_xml_path,
                          const OmniModelEdit& edit) {
  if (omni_xml_path.empty() && edit.is_identity()) return {};
  return [omni_xml_path, edit](mjModel* m) {
    if (!omni_xml_path.empty()) load_omni_parameters(m, omni_xml_path);
    apply_omni_edit(m, edit);
  };
}

}  // namespace vmh::sim
