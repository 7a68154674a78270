#include "cameras/rig_compare.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "core/errors.h"

namespace handlabel {

RigDifference CompareRigs(const Rig& a_in, const Rig& b_in, const std::string& reference,
                          const std::string& a_name, const std::string& b_name) {
  if (b_in.empty()) throw InputError(b_name, "cameras", "a non-empty rig");
  RigDifference out;
  out.reference = reference.empty() ? b_in[0].name : reference;
  Rig a = a_in, b = b_in;
  const int ia = a.IndexOf(out.reference), ib = b.IndexOf(out.reference);
  if (ia < 0 || ib < 0) {
    throw InputError(ia < 0 ? a_name : b_name, "reference camera",
                     "a camera in both rigs", "no camera '" + out.reference + "'");
  }
  a.SetWorldToCamera(ia);
  b.SetWorldToCamera(ib);
  out.worst.name = "max";
  for (const RigCamera& cb : b.cameras()) {
    if (a.IndexOf(cb.name) < 0) {
      throw InputError(a_name, "camera '" + cb.name + "'",
                       "the same camera names in both rigs", "only in " + b_name);
    }
    const RigCamera& ca = a.Find(cb.name);
    CameraDifference d;
    d.name = cb.name;
    d.focal_rel = std::max(std::abs(ca.camera.fx() / cb.camera.fx() - 1),
                           std::abs(ca.camera.fy() / cb.camera.fy() - 1));
    d.principal_px = std::max(std::abs(ca.camera.cx() - cb.camera.cx()),
                              std::abs(ca.camera.cy() - cb.camera.cy()));
    d.rotation_deg =
        RotationAngleBetween(ca.cam_from_world, cb.cam_from_world) * 180 / M_PI;
    d.centre_m = (ca.CenterInWorld() - cb.CenterInWorld()).norm();
    out.worst.focal_rel = std::max(out.worst.focal_rel, d.focal_rel);
    out.worst.principal_px = std::max(out.worst.principal_px, d.principal_px);
    out.worst.rotation_deg = std::max(out.worst.rotation_deg, d.rotation_deg);
    out.worst.centre_m = std::max(out.worst.centre_m, d.centre_m);
    out.cameras.push_back(d);
  }
  return out;
}

std::string RigDifferenceTable(const RigDifference& difference) {
  std::ostringstream out;
  out << "world at camera " << difference.reference << "\n"
      << std::left << std::setw(14) << "camera" << std::right << std::setw(12)
      << "focal %" << std::setw(16) << "principal px" << std::setw(14) << "rotation deg"
      << std::setw(13) << "centre mm"
      << "\n";
  std::vector<CameraDifference> rows = difference.cameras;
  rows.push_back(difference.worst);
  for (const CameraDifference& d : rows) {
    out << std::left << std::setw(14) << d.name << std::right << std::fixed
        << std::setprecision(4) << std::setw(12) << 100 * d.focal_rel
        << std::setprecision(3) << std::setw(16) << d.principal_px << std::setprecision(4)
        << std::setw(14) << d.rotation_deg << std::setprecision(3) << std::setw(13)
        << 1000 * d.centre_m << "\n";
  }
  return out.str();
}

}  // namespace handlabel
