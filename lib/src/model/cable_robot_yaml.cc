// YAML reading and writing of the cable robot model (format: docs/model-format.md).
//
// The model file is edited by hand and produced by calibration, so the reader is strict:
// every error names the file, the line (from yaml-cpp's Mark) and the key path, and
// unknown keys are errors so a misspelt key cannot silently fall back to the nominal
// value. Numbers are parsed and written with <charconv> (locale-independent); the writer
// emits the shortest decimal form that reads back to the same double (at most 17
// significant digits), so a save/load round trip is bit-exact.
#include <fcntl.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "fastcal/cable_robot.h"
#include "fastcal/internal/atomic_file.h"
#include "fastcal/internal/quote.h"
#include "fastcal/model_plausibility.h"
#include "util/yaml_document.h"

namespace fastcal {
namespace {

using internal::LineOf;
using internal::ShortestNumber;

constexpr char kFormatName[] = "fastcal-model-1";
constexpr char kRootPath[] = "(top level)";

// Key path for error messages: "cabin" + "mass_kg" -> "cabin.mass_kg".
std::string Join(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}
std::string Index(const std::string& parent, size_t i) {
  return parent + "[" + std::to_string(i) + "]";
}

// One key of a YAML mapping with its value.
struct Entry {
  YAML::Node key;
  YAML::Node value;
};

class Parser : public internal::YamlErrorRecorder {
 public:
  explicit Parser(const std::string& source) : YamlErrorRecorder(source) {}

  using YamlErrorRecorder::Fail;
  bool Fail(const YAML::Node& node, const std::string& path, const std::string& what) {
    return Fail(LineOf(node), path, what);
  }

  // Line of the key path, or of its nearest ancestor present in the file; 0 if none.
  int LineOfPath(std::string path) const {
    while (!path.empty()) {
      const auto it = lines_.find(path);
      if (it != lines_.end()) return it->second;
      const size_t cut = path.find_last_of(".[");
      if (cut == std::string::npos) break;
      path.resize(cut);
    }
    return 0;
  }

  // Reads a mapping into *entries, rejecting keys not in `allowed` and duplicates.
  bool ReadMap(const YAML::Node& node, int line, const std::string& path,
               const std::vector<std::string>& allowed, std::map<std::string, Entry>* entries) {
    if (!node.IsMap()) return Fail(line, path, "expected a mapping of keys");
    for (const auto& kv : node) {
      if (!kv.first.IsScalar()) return Fail(kv.first, path, "keys must be plain names");
      const std::string name = kv.first.Scalar();
      const std::string key_path = Join(path == kRootPath ? "" : path, name);
      bool known = false;
      for (const std::string& a : allowed) known = known || a == name;
      if (!known) {
        std::string list;
        for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
        return Fail(kv.first, key_path, "unknown key (allowed here: " + list + ")");
      }
      if (entries->count(name) != 0) return Fail(kv.first, key_path, "duplicate key");
      (*entries)[name] = Entry{kv.first, kv.second};
      lines_[key_path] = LineOf(kv.first);
    }
    return true;
  }

  bool ReadDouble(const YAML::Node& node, int line, const std::string& path, double* value) {
    if (node.IsNull()) return Fail(line, path, "has no value (expected a number)");
    if (!node.IsScalar()) return Fail(line, path, "expected a number");
    if (node.Tag() == "!") {
      return Fail(line, path,
                  "expected a number, got the quoted text " + internal::Quote(node.Scalar()));
    }
    const std::string& text = node.Scalar();
    const std::string lower = ToLower(text);
    if (lower == ".nan" || lower == ".inf" || lower == "+.inf" || lower == "-.inf") {
      return Fail(line, path, "must be finite, got " + internal::Quote(text));
    }
    // from_chars takes no leading '+'; YAML numbers may have one.
    const char* begin = text.data();
    const char* end = text.data() + text.size();
    if (begin != end && *begin == '+') ++begin;
    double parsed = 0.0;
    const auto [ptr, ec] = std::from_chars(begin, end, parsed);
    if (ec == std::errc::result_out_of_range)
      return Fail(line, path, "out of range: " + internal::Quote(text));
    if (ec != std::errc() || ptr != end || begin == end) {
      return Fail(line, path, "expected a number, got " + internal::Quote(text));
    }
    if (!std::isfinite(parsed))
      return Fail(line, path, "must be finite, got " + internal::Quote(text));
    *value = parsed;
    return true;
  }

  bool ReadInt(const YAML::Node& node, int line, const std::string& path, int* value) {
    if (node.IsNull()) return Fail(line, path, "has no value (expected an integer)");
    if (!node.IsScalar() || node.Tag() == "!") return Fail(line, path, "expected an integer");
    const std::string& text = node.Scalar();
    int parsed = 0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), parsed);
    if (ec != std::errc() || ptr != text.data() + text.size() || text.empty()) {
      return Fail(line, path, "expected an integer, got " + internal::Quote(text));
    }
    *value = parsed;
    return true;
  }

  // A flow or block list of exactly three numbers.
  bool ReadVector3(const YAML::Node& node, int line, const std::string& path,
                   Eigen::Vector3d* value) {
    if (!node.IsSequence() || node.size() != 3) {
      const std::string got =
          node.IsSequence() ? std::to_string(node.size()) + " entries" : "no list";
      return Fail(line, path, "expected a list of 3 numbers [x, y, z], got " + got);
    }
    Eigen::Vector3d v;
    for (size_t k = 0; k < 3; ++k) {
      const int element_line = LineOf(node[k]) > 0 ? LineOf(node[k]) : line;
      if (!ReadDouble(node[k], element_line, Index(path, k), &v[k])) return false;
    }
    *value = v;
    return true;
  }

  // The cabin's inertia: [Ixx, Iyy, Izz] (principal axes along the cabin frame's) or a
  // 3x3 list of rows.
  bool ReadInertia(const YAML::Node& node, int line, const std::string& path,
                   Eigen::Matrix3d* value) {
    if (node.IsSequence() && node.size() == 3 && !node[0].IsSequence()) {
      Eigen::Vector3d diagonal;
      if (!ReadVector3(node, line, path, &diagonal)) return false;
      *value = diagonal.asDiagonal();
      return true;
    }
    if (!node.IsSequence() || node.size() != 3) {
      return Fail(line, path, "expected [Ixx, Iyy, Izz] or three rows [[Ixx, Ixy, Ixz], ...]");
    }
    Eigen::Matrix3d m;
    for (size_t r = 0; r < 3; ++r) {
      Eigen::Vector3d row;
      const int row_line = LineOf(node[r]) > 0 ? LineOf(node[r]) : line;
      if (!ReadVector3(node[r], row_line, Index(path, r), &row)) return false;
      m.row(r) = row.transpose();
    }
    *value = m;
    return true;
  }

  bool ReadCabin(const Entry& cabin, CableRobot* robot) {
    const std::string path = "cabin";
    std::map<std::string, Entry> keys;
    if (!ReadMap(cabin.value, LineOf(cabin.key), path,
                 {"mass_kg", "mass_centre_m", "inertia_kg_m2", "anchor_points_m", "moving_parts",
                  "measured_frame"},
                 &keys)) {
      return false;
    }
    if (const auto it = keys.find("moving_parts"); it != keys.end()) {
      if (!ReadMovingParts(it->second, &robot->moving_parts)) return false;
    }
    if (const auto it = keys.find("measured_frame"); it != keys.end()) {  // names a part
      MeasuredFrame frame;
      if (!ReadMeasuredFrame(it->second, robot->moving_parts, &frame)) return false;
      robot->measured_frame = frame;
    }
    if (const auto it = keys.find("inertia_kg_m2"); it != keys.end()) {
      if (!ReadInertia(it->second.value, LineOf(it->second.key), Join(path, "inertia_kg_m2"),
                       &robot->cabin_inertia_kg_m2)) {
        return false;
      }
    }
    if (const auto it = keys.find("mass_kg"); it != keys.end()) {
      if (!ReadDouble(it->second.value, LineOf(it->second.key), Join(path, "mass_kg"),
                      &robot->cabin_mass_kg)) {
        return false;
      }
    }
    if (const auto it = keys.find("mass_centre_m"); it != keys.end()) {
      if (!ReadVector3(it->second.value, LineOf(it->second.key), Join(path, "mass_centre_m"),
                       &robot->mass_centre_cabin_m)) {
        return false;
      }
    }
    if (const auto it = keys.find("anchor_points_m"); it != keys.end()) {
      const std::string list_path = Join(path, "anchor_points_m");
      const YAML::Node& list = it->second.value;
      const int line = LineOf(it->second.key);
      if (!list.IsSequence() || list.size() == 0) {
        return Fail(line, list_path, "expected a list of at least one point [x, y, z]");
      }
      std::vector<Eigen::Vector3d> points(list.size());
      for (size_t j = 0; j < list.size(); ++j) {
        const std::string point_path = Index(list_path, j);
        const int point_line = LineOf(list[j]) > 0 ? LineOf(list[j]) : line;
        lines_[point_path] = point_line;
        if (!ReadVector3(list[j], point_line, point_path, &points[j])) return false;
      }
      robot->anchor_points_cabin_m = std::move(points);
    }
    return true;
  }

  // cabin.measured_frame: {part: NAME or cabin, offset_m: [x, y, z]} (measured_frame.h).
  bool ReadMeasuredFrame(const Entry& entry, const MovingParts& parts, MeasuredFrame* frame) {
    const std::string path = "cabin.measured_frame";
    std::map<std::string, Entry> keys;
    if (!ReadMap(entry.value, LineOf(entry.key), path, {"part", "offset_m"}, &keys)) return false;
    if (const auto it = keys.find("part"); it != keys.end()) {
      std::string name;
      if (!ReadName(it->second, Join(path, "part"), &name)) return false;
      if (name != "cabin") {
        frame->part = parts.Find(name);
        if (frame->part < 0) {
          std::string names;
          for (const MovingPart& p : parts.parts) names += p.name + ", ";
          return Fail(it->second.key, Join(path, "part"),
                      "'" + name + "' is not a moving part of the model (" +
                          (parts.empty() ? std::string("it has none; cabin.moving_parts")
                                         : "its parts: " + names.substr(0, names.size() - 2)) +
                          "; or cabin)");
        }
      }
    }
    if (const auto it = keys.find("offset_m"); it != keys.end()) {
      return ReadVector3(it->second.value, LineOf(it->second.key), Join(path, "offset_m"),
                         &frame->offset_m);
    }
    return true;
  }

  // cabin.moving_parts: a list of parts (moving_parts.h), each with its joints.
  bool ReadMovingParts(const Entry& entry, MovingParts* out) {
    const std::string path = "cabin.moving_parts";
    const YAML::Node& list = entry.value;
    const int line = LineOf(entry.key);
    out->parts.clear();
    if (list.IsNull()) return true;  // `moving_parts:` with nothing: none
    if (!list.IsSequence()) return Fail(line, path, "expected a list of parts");
    for (size_t k = 0; k < list.size(); ++k) {
      const std::string part_path = Index(path, k);
      const int part_line = LineOf(list[k]) > 0 ? LineOf(list[k]) : line;
      lines_[part_path] = part_line;
      MovingPart part;
      if (!ReadMovingPart(list[k], part_line, part_path, *out, &part)) return false;
      out->parts.push_back(std::move(part));
    }
    return true;
  }

  bool ReadMovingPart(const YAML::Node& node, int line, const std::string& path,
                      const MovingParts& earlier, MovingPart* part) {
    std::map<std::string, Entry> keys;
    if (!ReadMap(node, line, path,
                 {"name", "parent", "joints", "origin_m", "first_moment_kg_m", "mass_kg"}, &keys)) {
      return false;
    }
    for (const char* name : {"name", "joints"}) {
      if (keys.count(name) == 0) {
        return Fail(line, Join(path, name), "missing (each part gives a name and its joints)");
      }
    }
    if (!ReadName(keys["name"], Join(path, "name"), &part->name)) return false;
    if (keys.count("parent")) {
      std::string parent;
      if (!ReadName(keys["parent"], Join(path, "parent"), &parent)) return false;
      if (parent != "cabin") {
        part->parent = earlier.Find(parent);
        if (part->parent < 0) {
          return Fail(keys["parent"].key, Join(path, "parent"),
                      "'" + parent + "' is not a part listed before this one (or cabin)");
        }
      }
    }
    const std::vector<std::pair<const char*, Eigen::Vector3d*>> vectors = {
        {"origin_m", &part->origin_m}, {"first_moment_kg_m", &part->first_moment_kg_m}};
    for (const auto& [name, value] : vectors) {
      const auto it = keys.find(name);
      if (it != keys.end() &&
          !ReadVector3(it->second.value, LineOf(it->second.key), Join(path, name), value)) {
        return false;
      }
    }
    if (keys.count("mass_kg") && !ReadDouble(keys["mass_kg"].value, LineOf(keys["mass_kg"].key),
                                             Join(path, "mass_kg"), &part->mass_kg)) {
      return false;
    }
    return ReadJoints(keys["joints"], Join(path, "joints"), &part->joints);
  }

  bool ReadName(const Entry& entry, const std::string& path, std::string* out) {
    if (!entry.value.IsScalar() || entry.value.Scalar().empty()) {
      return Fail(entry.key, path, "expected a name");
    }
    *out = entry.value.Scalar();
    return true;
  }

  // A list of {type, axis, column[, range]}; range in the column's unit (deg or m).
  bool ReadJoints(const Entry& entry, const std::string& path, std::vector<Joint>* out) {
    const YAML::Node& list = entry.value;
    if (!list.IsSequence() || list.size() == 0) {
      return Fail(entry.key, path, "expected a list of at least one joint {type, axis, column}");
    }
    for (size_t j = 0; j < list.size(); ++j) {
      const std::string jpath = Index(path, j);
      const int jline = LineOf(list[j]) > 0 ? LineOf(list[j]) : LineOf(entry.key);
      lines_[jpath] = jline;
      std::map<std::string, Entry> keys;
      if (!ReadMap(list[j], jline, jpath, {"type", "axis", "column", "range"}, &keys)) return false;
      for (const char* name : {"type", "axis", "column"}) {
        if (keys.count(name) == 0) {
          return Fail(jline, Join(jpath, name), "missing (each joint gives type, axis and column)");
        }
      }
      Joint joint;
      const YAML::Node& type = keys["type"].value;
      const std::string type_text = type.IsScalar() ? type.Scalar() : "";
      if (type_text != "revolute" && type_text != "prismatic") {
        return Fail(keys["type"].key, Join(jpath, "type"),
                    "expected revolute or prismatic, got '" + type_text + "'");
      }
      joint.type = type_text == "revolute" ? JointType::kRevolute : JointType::kPrismatic;
      if (!ReadVector3(keys["axis"].value, LineOf(keys["axis"].key), Join(jpath, "axis"),
                       &joint.axis)) {
        return false;
      }
      if (!(joint.axis.norm() > 0.0)) {
        return Fail(keys["axis"].key, Join(jpath, "axis"), "must be a non-zero vector");
      }
      joint.axis.normalize();
      if (!ReadName(keys["column"], Join(jpath, "column"), &joint.column)) return false;
      if (keys.count("range") && !ReadRange(keys["range"], Join(jpath, "range"), &joint)) {
        return false;
      }
      out->push_back(joint);
    }
    return true;
  }

  bool ReadRange(const Entry& entry, const std::string& path, Joint* joint) {
    const YAML::Node& node = entry.value;
    const int line = LineOf(entry.key);
    if (!node.IsSequence() || node.size() != 2) {
      return Fail(line, path, "expected [low, high] in the column's unit (deg or m)");
    }
    double low = 0.0, high = 0.0;
    if (!ReadDouble(node[0], line, Index(path, 0), &low) ||
        !ReadDouble(node[1], line, Index(path, 1), &high)) {
      return false;
    }
    if (!(low < high)) return Fail(line, path, "expected low < high");
    joint->has_range = true;
    joint->range_low = low;
    joint->range_high = high;
    return true;
  }

  bool ReadCables(const Entry& cables, CableRobot* robot) {
    const std::string path = "cables";
    const YAML::Node& list = cables.value;
    const int line = LineOf(cables.key);
    if (!list.IsSequence()) return Fail(line, path, "expected a list of 6 cables");
    if (list.size() != kNumCables) {
      return Fail(line, path,
                  "expected exactly 6 entries (cable 1 first), got " + std::to_string(list.size()));
    }
    for (size_t i = 0; i < kNumCables; ++i) {
      const std::string cable_path = Index(path, i);
      const int cable_line = LineOf(list[i]) > 0 ? LineOf(list[i]) : line;
      lines_[cable_path] = cable_line;
      const std::vector<std::string> required = {"tower_top_m", "anchor", "ea_n",
                                                 "linear_density_kg_per_m"};
      std::vector<std::string> allowed = required;
      allowed.push_back("sensor_gain");      // optional, default 1
      allowed.push_back("sensor_bias_kN");   // optional, default 0
      allowed.push_back("length_offset_m");  // optional, default 0
      allowed.push_back("attachments");      // optional, default none
      std::map<std::string, Entry> keys;
      if (!ReadMap(list[i], cable_line, cable_path, allowed, &keys)) return false;
      for (const std::string& name : required) {
        if (keys.count(name) == 0) {
          return Fail(cable_line, Join(cable_path, name),
                      "missing (each cable must give tower_top_m, anchor, ea_n and "
                      "linear_density_kg_per_m)");
        }
      }
      CableProperties& c = robot->cables[i];
      const Entry& tower = keys["tower_top_m"];
      const Entry& anchor = keys["anchor"];
      const Entry& ea = keys["ea_n"];
      const Entry& density = keys["linear_density_kg_per_m"];
      if (!ReadVector3(tower.value, LineOf(tower.key), Join(cable_path, "tower_top_m"),
                       &c.tower_top_m) ||
          !ReadInt(anchor.value, LineOf(anchor.key), Join(cable_path, "anchor"), &c.anchor_index) ||
          !ReadDouble(ea.value, LineOf(ea.key), Join(cable_path, "ea_n"), &c.ea_n) ||
          !ReadDouble(density.value, LineOf(density.key),
                      Join(cable_path, "linear_density_kg_per_m"), &c.linear_density_kg_per_m)) {
        return false;
      }
      c.sensor_gain = 1.0;
      c.sensor_bias_n = 0.0;
      if (keys.count("sensor_gain") &&
          !ReadDouble(keys["sensor_gain"].value, LineOf(keys["sensor_gain"].key),
                      Join(cable_path, "sensor_gain"), &c.sensor_gain)) {
        return false;
      }
      if (keys.count("sensor_bias_kN")) {
        double bias_kn = 0.0;
        if (!ReadDouble(keys["sensor_bias_kN"].value, LineOf(keys["sensor_bias_kN"].key),
                        Join(cable_path, "sensor_bias_kN"), &bias_kn)) {
          return false;
        }
        c.sensor_bias_n = bias_kn * 1e3;
      }
      c.length_offset_m = 0.0;
      if (keys.count("length_offset_m") &&
          !ReadDouble(keys["length_offset_m"].value, LineOf(keys["length_offset_m"].key),
                      Join(cable_path, "length_offset_m"), &c.length_offset_m)) {
        return false;
      }
      c.attachments.clear();
      if (keys.count("attachments") &&
          !ReadAttachments(keys["attachments"], Join(cable_path, "attachments"), &c.attachments)) {
        return false;
      }
    }
    return true;
  }

  // A list of {at_m, mass_kg} (point masses) and {from_m, to_m, added_density_kg_per_m}
  // (added weight over a range), each with all of its keys (cable_attachment.h).
  bool ReadAttachments(const Entry& entry, const std::string& path,
                       std::vector<CableAttachment>* out) {
    const YAML::Node& list = entry.value;
    const int line = LineOf(entry.key);
    if (list.IsNull()) return true;  // `attachments:` with nothing: none
    if (!list.IsSequence()) {
      return Fail(line, path,
                  "expected a list of {at_m, mass_kg} and {from_m, to_m, "
                  "added_density_kg_per_m} entries");
    }
    for (size_t j = 0; j < list.size(); ++j) {
      const std::string item_path = Index(path, j);
      const int item_line = LineOf(list[j]) > 0 ? LineOf(list[j]) : line;
      lines_[item_path] = item_line;
      std::map<std::string, Entry> keys;
      if (!ReadMap(list[j], item_line, item_path,
                   {"at_m", "mass_kg", "from_m", "to_m", "added_density_kg_per_m"}, &keys)) {
        return false;
      }
      CableAttachment a;
      const bool point = keys.count("at_m") || keys.count("mass_kg");
      a.kind = point ? AttachmentKind::kPointMass : AttachmentKind::kAddedDensity;
      const std::vector<std::pair<const char*, double*>> fields = a.Fields();
      if (keys.size() != fields.size()) {
        return Fail(item_line, item_path, CableAttachment::KeysText(a.kind));
      }
      for (const auto& [name, value] : fields) {
        const auto it = keys.find(name);
        if (it == keys.end()) {
          return Fail(item_line, Join(item_path, name),
                      point ? "missing (a point mass gives at_m and mass_kg)"
                            : "missing (added weight gives from_m, to_m and "
                              "added_density_kg_per_m)");
        }
        if (!ReadDouble(it->second.value, LineOf(it->second.key), Join(item_path, name), value)) {
          return false;
        }
      }
      out->push_back(a);
    }
    return true;
  }

  // `reflector: none`, or a mapping whose absent keys keep the nominal values.
  bool ReadReflector(const Entry& entry, CableRobot* robot) {
    const std::string path = "reflector";
    const YAML::Node& node = entry.value;
    const int line = LineOf(entry.key);
    if (node.IsScalar() && node.Tag() != "!" && node.Scalar() == "none") {
      robot->reflector.reset();
      return true;
    }
    if (!node.IsMap()) {
      return Fail(line, path, "expected a mapping (centre_m, radius_m, aperture_m) or none");
    }
    std::map<std::string, Entry> keys;
    if (!ReadMap(node, line, path, {"centre_m", "radius_m", "aperture_m"}, &keys)) return false;
    Reflector reflector;
    if (const auto it = keys.find("centre_m"); it != keys.end()) {
      if (!ReadVector3(it->second.value, LineOf(it->second.key), Join(path, "centre_m"),
                       &reflector.centre_m)) {
        return false;
      }
    }
    for (const auto& [name, value] : {std::pair{"radius_m", &reflector.radius_m},
                                      std::pair{"aperture_m", &reflector.aperture_m}}) {
      if (const auto it = keys.find(name); it != keys.end()) {
        if (!ReadDouble(it->second.value, LineOf(it->second.key), Join(path, name), value)) {
          return false;
        }
      }
    }
    robot->reflector = reflector;
    return true;
  }

  bool ReadRoot(const YAML::Node& root, CableRobot* robot) {
    std::map<std::string, Entry> keys;
    if (!ReadMap(root, LineOf(root), kRootPath,
                 {"format", "gravity_m_per_s2", "cabin", "cables", "reflector"}, &keys)) {
      return false;
    }
    if (const auto it = keys.find("format"); it != keys.end()) {
      const YAML::Node& v = it->second.value;
      if (!v.IsScalar() || v.Scalar() != kFormatName) {
        return Fail(
            it->second.key, "format",
            std::string("must be ") + kFormatName + (v.IsScalar() ? ", got " + v.Scalar() : ""));
      }
    }
    if (const auto it = keys.find("gravity_m_per_s2"); it != keys.end()) {
      if (!ReadDouble(it->second.value, LineOf(it->second.key), "gravity_m_per_s2",
                      &robot->gravity_m_per_s2)) {
        return false;
      }
    }
    if (const auto it = keys.find("cabin"); it != keys.end()) {
      if (!ReadCabin(it->second, robot)) return false;
    }
    if (const auto it = keys.find("cables"); it != keys.end()) {
      if (!ReadCables(it->second, robot)) return false;
    }
    if (const auto it = keys.find("reflector"); it != keys.end()) {
      if (!ReadReflector(it->second, robot)) return false;
    }
    return true;
  }

  // Turns IsValid's message (struct field names) into YAML key paths with a line.
  bool FailValidation(std::string message) {
    const std::pair<const char*, const char*> kRenames[] = {
        {"anchor_points_cabin_m", "cabin.anchor_points_m"},
        {"mass_centre_cabin_m", "cabin.mass_centre_m"},
        {"cabin_mass_kg", "cabin.mass_kg"},
        {"cabin_inertia_kg_m2", "cabin.inertia_kg_m2"},
    };
    for (const auto& [from, to] : kRenames) {
      for (size_t pos = message.find(from); pos != std::string::npos;
           pos = message.find(from, pos + std::strlen(to))) {
        message.replace(pos, std::strlen(from), to);
      }
    }
    const size_t colon = message.find(": ");
    const std::string path = message.substr(0, colon);
    const std::string what = colon == std::string::npos ? "invalid" : message.substr(colon + 2);
    return Fail(LineOfPath(path), path, what);
  }

 private:
  static std::string ToLower(std::string s) {
    for (char& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    return s;
  }

  // Line of each key path read from the file, for validation errors.
  std::map<std::string, int> lines_;
};

std::string Vec(const Eigen::Vector3d& v) {
  return "[" + ShortestNumber(v.x()) + ", " + ShortestNumber(v.y()) + ", " + ShortestNumber(v.z()) +
         "]";
}

// cabin.moving_parts as ReadMovingParts reads it (ranges back in the column's unit).
void WriteMovingParts(const MovingParts& moving, std::ostringstream& out) {
  if (moving.empty()) return;
  out << "  moving_parts:  # joints applied in order; values from the data's columns\n";
  for (const MovingPart& p : moving.parts) {
    out << "    - name: " << p.name << "\n";
    if (p.parent >= 0) out << "      parent: " << moving.parts[p.parent].name << "\n";
    out << "      joints:\n";
    for (const Joint& j : p.joints) {
      out << "        - {type: " << JointTypeName(j.type) << ", axis: " << Vec(j.axis)
          << ", column: " << j.column;
      if (j.has_range) {
        out << ", range: [" << ShortestNumber(j.range_low) << ", " << ShortestNumber(j.range_high)
            << "]";
      }
      out << "}\n";
    }
    out << "      origin_m: " << Vec(p.origin_m) << "  # parent frame\n";
    out << "      first_moment_kg_m: " << Vec(p.first_moment_kg_m)
        << "  # own mass x centre, about origin_m, joints at zero\n";
    if (p.mass_kg != 0.0) out << "      mass_kg: " << ShortestNumber(p.mass_kg) << "\n";
  }
}

// [Ixx, Iyy, Izz] when the tensor is diagonal, else its three rows.
std::string InertiaText(const Eigen::Matrix3d& inertia) {
  if (inertia.isDiagonal(0.0)) return Vec(inertia.diagonal());
  return "[" + Vec(inertia.row(0)) + ", " + Vec(inertia.row(1)) + ", " + Vec(inertia.row(2)) + "]";
}

}  // namespace

bool ParseCableRobotYaml(const std::string& text, const std::string& source_name, CableRobot* robot,
                         std::string* error) {
  Parser parser(source_name);
  CableRobot parsed = CableRobot::NominalFast();
  try {
    const internal::YamlDocuments documents = internal::LoadYamlDocuments(text);
    if (documents.count > 1) {
      parser.Fail(documents.second_line, kRootPath, "only one YAML document is allowed");
    } else if (documents.first.IsNull()) {
      // Most likely a truncated or wrong file: the nominal model is had without one.
      parser.FailFile("empty model file: omit the model file for the nominal FAST layout");
    } else if (parser.ReadRoot(documents.first, &parsed)) {
      std::string why;
      if (!CheckModel(parsed, &why)) {
        parser.FailValidation(why);
      }
    }
  } catch (const YAML::Exception& e) {
    const int line = e.mark.line < 0 ? 0 : e.mark.line + 1;
    parser.Fail(line, "YAML syntax error", e.msg);
  }
  if (!parser.error().empty()) {
    if (error != nullptr) *error = parser.error();
    return false;
  }
  *robot = std::move(parsed);
  return true;
}

bool LoadCableRobot(const std::string& path, CableRobot* robot, std::string* error) {
  std::string text;
  std::string message;
  if (!internal::ReadRegularFile(path, kMaxModelFileBytes, "model", &text, &message)) {
    if (error != nullptr) *error = message;
    return false;
  }
  return ParseCableRobotYaml(text, path, robot, error);
}

std::string CableRobotToYaml(const CableRobot& robot, const std::string& header_comment) {
  std::ostringstream out;
  if (!header_comment.empty()) {
    std::istringstream lines(header_comment);
    for (std::string line; std::getline(lines, line);) {
      out << (line.empty() ? "#" : "# " + line) << "\n";
    }
  }
  out << "format: " << kFormatName << "\n";
  out << "gravity_m_per_s2: " << ShortestNumber(robot.gravity_m_per_s2) << "  # m/s^2, z up\n";
  out << "cabin:\n";
  out << "  mass_kg: " << ShortestNumber(robot.cabin_mass_kg) << "\n";
  out << "  mass_centre_m: " << Vec(robot.mass_centre_cabin_m) << "  # cabin frame\n";
  out << "  inertia_kg_m2: " << InertiaText(robot.cabin_inertia_kg_m2)
      << "  # about the mass centre, cabin frame (vibrations only)\n";
  out << "  anchor_points_m:  # cabin frame, m\n";
  for (const Eigen::Vector3d& a : robot.anchor_points_cabin_m) out << "    - " << Vec(a) << "\n";
  WriteMovingParts(robot.moving_parts, out);
  if (robot.measured_frame.has_value()) {
    const MeasuredFrame& f = *robot.measured_frame;
    out << "  measured_frame:  # whose pose the data's x_m..z_m and attitude give\n";
    out << "    part: "
        << (f.part < 0 ? std::string("cabin") : robot.moving_parts.parts[f.part].name) << "\n";
    out << "    offset_m: " << Vec(f.offset_m) << "  # the measured point, in that part's frame\n";
  }
  out << "cables:  # cable 1 first; tower tops in the global frame, m\n";
  for (int i = 0; i < kNumCables; ++i) {
    const CableProperties& c = robot.cables[i];
    out << "  - tower_top_m: " << Vec(c.tower_top_m) << "  # cable " << i + 1 << "\n";
    out << "    anchor: " << c.anchor_index << "  # index into cabin.anchor_points_m\n";
    out << "    ea_n: " << ShortestNumber(c.ea_n) << "  # N\n";
    out << "    linear_density_kg_per_m: " << ShortestNumber(c.linear_density_kg_per_m) << "\n";
    if (c.sensor_gain != 1.0 || c.sensor_bias_n != 0.0) {
      out << "    sensor_gain: " << ShortestNumber(c.sensor_gain)
          << "  # reading = gain * tension + bias\n";
      out << "    sensor_bias_kN: " << ShortestNumber(c.sensor_bias_n / 1e3) << "\n";
    }
    if (c.length_offset_m != 0.0) {
      out << "    length_offset_m: " << ShortestNumber(c.length_offset_m)
          << "  # encoder reading = unstretched length + offset\n";
    }
    if (!c.attachments.empty()) {
      out << "    attachments:  # arc length from the lower (cabin) end, unstretched, m\n";
      for (const CableAttachment& a : c.attachments) {
        if (a.kind == AttachmentKind::kPointMass) {
          out << "      - {at_m: " << ShortestNumber(a.at_m)
              << ", mass_kg: " << ShortestNumber(a.mass_kg) << "}\n";
        } else {
          out << "      - {from_m: " << ShortestNumber(a.from_m)
              << ", to_m: " << ShortestNumber(a.to_m)
              << ", added_density_kg_per_m: " << ShortestNumber(a.added_density_kg_per_m) << "}\n";
        }
      }
    }
  }
  if (robot.reflector.has_value()) {
    out << "reflector:  # lower cap of a sphere, global frame, m\n";
    out << "  centre_m: " << Vec(robot.reflector->centre_m) << "\n";
    out << "  radius_m: " << ShortestNumber(robot.reflector->radius_m) << "\n";
    out << "  aperture_m: " << ShortestNumber(robot.reflector->aperture_m) << "  # rim diameter\n";
  } else {
    out << "reflector: none  # not modelled: no contact check\n";
  }
  return out.str();
}

bool SaveCableRobot(const CableRobot& robot, const std::string& path,
                    const std::string& header_comment, std::string* error) {
  const std::string text = CableRobotToYaml(robot, header_comment);
  return internal::WriteFileAtomically(path, text, error);
}

}  // namespace fastcal
