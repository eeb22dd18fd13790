// fastcal.Dataset (dataset.h): telemetry as numpy arrays, read, written and simulated
// (simulation.h).
#include <pybind11/stl.h>

#include <charconv>
#include <cmath>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "bindings.h"
#include "fastcal/cable_robot.h"
#include "fastcal/column_map.h"
#include "fastcal/dataset.h"
#include "fastcal/sessions.h"
#include "fastcal/simulation.h"

namespace fastcal::python {
namespace {

// One (n, columns) array of a per-sample quantity.
template <typename Fill>
DoubleArray PerSample(const Dataset& d, py::ssize_t columns, Fill fill) {
  DoubleArray out = NewArray({static_cast<py::ssize_t>(d.samples.size()), columns});
  for (size_t n = 0; n < d.samples.size(); ++n) {
    fill(d.samples[n], out.mutable_data() + static_cast<py::ssize_t>(n) * columns);
  }
  return out;
}

// The measured attitude as roll/pitch/yaw: the file's numbers when it gave them.
Eigen::Vector3d MeasuredRpyDeg(const Dataset& d, const Sample& s) {
  return d.attitude_as_quaternion ? RpyDegFromRotation(s.pose.rotation) : s.measured_rpy_deg;
}
Eigen::Vector4d MeasuredQuat(const Dataset& d, const Sample& s) {
  return d.attitude_as_quaternion ? s.measured_quaternion_wxyz
                                  : QuaternionFromRotation(s.pose.rotation);
}

SimulationOptions MakeSimulationOptions(const py::dict& kwargs) {
  SimulationOptions o;
  const std::vector<std::pair<const char*, double*>> doubles = {
      {"attitude_control_sigma_deg", &o.attitude_control_sigma_deg},
      {"attitude_control_time_s", &o.attitude_control_time_s},
      {"tension_drift_percent", &o.tension_drift_percent},
      {"tension_drift_time_s", &o.tension_drift_time_s},
      {"mass_centre_drift_m", &o.mass_centre_drift_m},
      {"mass_centre_drift_time_s", &o.mass_centre_drift_time_s},
      {"sensor_gain_spread_percent", &o.sensor_gain_spread_percent},
      {"sensor_bias_spread_kn", &o.sensor_bias_spread_kn},
      {"attitude_measurement_sigma_deg", &o.attitude_measurement_sigma_deg},
      {"position_measurement_sigma_m", &o.position_measurement_sigma_m},
      {"tension_noise_percent", &o.tension_noise_percent},
      {"tension_noise_kn", &o.tension_noise_kn},
      {"outlier_fraction", &o.outlier_fraction},
      {"outlier_scale_percent", &o.outlier_scale_percent},
      {"density_mismatch_percent", &o.density_mismatch_percent},
      {"length_offset_spread_m", &o.length_offset_spread_m},
      {"length_noise_m", &o.length_noise_m},
      {"sample_interval_s", &o.sample_interval_s},
      {"start_time_s", &o.start_time_s},
      {"session_gap_s", &o.session_gap_s}};
  for (const auto& [key, value] : kwargs) {
    const std::string name = py::str(key);
    bool known = false;
    for (const auto& [field, target] : doubles) {
      if (name == field) {
        *target = value.cast<double>();
        known = true;
      }
    }
    if (name == "seed") {
      o.seed = value.cast<std::uint64_t>();
    } else if (name == "sessions") {
      o.sessions = value.cast<int>();
    } else if (name == "mass_centre_steps") {
      // [(time_s, (dx, dy, dz)), ...]
      for (const py::handle step : value) {
        const auto pair = step.cast<std::pair<double, std::vector<double>>>();
        if (pair.second.size() != 3) {
          throw InputError("simulate: each of mass_centre_steps is (time_s, (dx, dy, dz))");
        }
        o.mass_centre_steps.push_back(
            {pair.first, Eigen::Vector3d(pair.second[0], pair.second[1], pair.second[2])});
      }
    } else if (name == "sensor_bias_steps") {
      // [(time_s, cable 1..6, shift_kN), ...]
      for (const py::handle step : value) {
        const auto t = step.cast<std::tuple<double, int, double>>();
        o.sensor_bias_steps.push_back(
            {std::get<0>(t), std::get<1>(t) - 1, std::get<2>(t) * kNPerKn});
      }
    } else if (name == "method") {
      if (!ParseStaticsMethod(value.cast<std::string>(), &o.method)) {
        throw InputError("method must be 'aas', 'aas-refined' or 'exact'");
      }
    } else if (!known) {
      throw InputError("simulate: unknown option '" + name + "'");
    }
  }
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  return o;
}

py::dict SummaryDict(const SimulationSummary& s) {
  py::dict d;
  DoubleArray rms_kn = NewArray({kNumCables}), rms_rel = NewArray({kNumCables}),
              density = NewArray({kNumCables}), drift = NewArray({kNumCables});
  py::array_t<int> outliers(kNumCables);
  for (int i = 0; i < kNumCables; ++i) {
    rms_kn.mutable_data()[i] = s.tension_noise_rms_n[i] / kNPerKn;
    rms_rel.mutable_data()[i] = s.tension_noise_rms_relative[i];
    density.mutable_data()[i] = s.density_factor[i];
    drift.mutable_data()[i] = s.tension_drift_rms_relative[i];
    outliers.mutable_data()[i] = s.outliers[i];
  }
  d["samples"] = s.samples;
  d["tension_noise_rms_kN"] = rms_kn;
  d["tension_noise_rms_relative"] = rms_rel;
  d["outliers"] = outliers;
  d["redrawn"] = s.redrawn;
  d["attitude_control_rms_deg"] = s.attitude_control_rms_deg;
  d["attitude_measurement_rms_deg"] = s.attitude_measurement_rms_deg;
  d["position_measurement_rms_m"] = s.position_measurement_rms_m;
  d["density_factor"] = density;
  d["tension_drift_rms_relative"] = drift;
  d["mass_centre_mean_m"] =
      std::vector<double>(s.mass_centre_mean_m.data(), s.mass_centre_mean_m.data() + 3);
  d["mass_centre_drift_rms_m"] = s.mass_centre_drift_rms_m;
  d["length_offset_m"] = std::vector<double>(s.length_offset_m.begin(), s.length_offset_m.end());
  d["length_noise_rms_m"] =
      std::vector<double>(s.length_noise_rms_m.begin(), s.length_noise_rms_m.end());
  return d;
}

}  // namespace

std::shared_ptr<const ColumnMap> MapOrThrow(const std::string& map_text,
                                            const std::string& map_source, bool csv_layout,
                                            bool header_first) {
  if (map_text.empty()) return nullptr;
  auto map = std::make_shared<ColumnMap>();
  std::string error;
  if (!ParseColumnMap(map_text, map_source, map.get(), &error)) throw InputError(error);
  if (csv_layout) map->delimiter = ',';
  if (header_first) {
    map->header_line = 1;
    map->skip_after_header = 0;
    map->decimal = '.';
  }
  return map;
}

namespace {

// One file, or several merged as one session each (sessions.h).
Dataset ReadDatasetOrThrow(const std::vector<std::string>& paths, bool skip_invalid_rows,
                           const std::string& map_text, const std::string& map_source,
                           const std::vector<std::string>& joint_columns) {
  DatasetReadOptions options;
  options.joint_columns = joint_columns;
  options.skip_invalid_rows = skip_invalid_rows;
  options.columns = MapOrThrow(map_text, map_source, false, false);
  Dataset data;
  std::string error;
  bool ok = false;
  for (const std::string& path : paths) RequireExistingFile(path, "dataset");
  {
    py::gil_scoped_release release;
    ok = ReadSessionDatasets(paths, options, &data, &error);
  }
  if (!ok) throw InputError(error);
  return data;
}

void BindDatasetClass(py::module_& m) {
  py::class_<Dataset>(m, "Dataset", R"(Measured telemetry (docs/data-format.md), one row per sample.

Arrays are copies, in file order: time_s (n,), position_m (n, 3), rpy_deg (n, 3) and
quat (n, 4) the measured attitude, tension_kN (n, 6), line (n,) the file's 1-based line
of each sample; planned_rpy_deg (n, 3) and s0_m (n, 6) are None when the file lacks
those columns. skipped lists the rows read_dataset(skip_invalid_rows=True) left out.
session_labels lists the sessions (a session column, or one per file read together) in
the order of their first sample, empty without; session (n,) each sample's index into it.
)")
      .def("__len__", [](const Dataset& d) { return d.samples.size(); })
      .def_readonly("path", &Dataset::path)
      .def_readonly("skipped", &Dataset::skipped)
      .def_readonly("session_labels", &Dataset::session_labels)
      .def_readonly("time_offset_s", &Dataset::time_offset_s,
                    "The zone its times are shown in (the column map's), seconds east of UTC.")
      .def_property_readonly("session",
                             [](const Dataset& d) {
                               py::array_t<int> out(static_cast<py::ssize_t>(d.samples.size()));
                               for (size_t n = 0; n < d.samples.size(); ++n) {
                                 out.mutable_data()[n] = d.samples[n].session;
                               }
                               return out;
                             })
      .def_property_readonly("time_s",
                             [](const Dataset& d) {
                               return PerSample(d, 1,
                                                [](const Sample& s, double* o) { *o = s.time_s; })
                                   .attr("reshape")(-1);
                             })
      .def_property_readonly("line",
                             [](const Dataset& d) {
                               py::array_t<int> out(static_cast<py::ssize_t>(d.samples.size()));
                               for (size_t n = 0; n < d.samples.size(); ++n) {
                                 out.mutable_data()[n] = d.samples[n].line;
                               }
                               return out;
                             })
      .def_property_readonly("position_m",
                             [](const Dataset& d) {
                               return PerSample(d, 3, [](const Sample& s, double* o) {
                                 for (int k = 0; k < 3; ++k) o[k] = s.pose.position_m[k];
                               });
                             })
      .def_property_readonly("rpy_deg",
                             [](const Dataset& d) {
                               return PerSample(d, 3, [&d](const Sample& s, double* o) {
                                 const Eigen::Vector3d a = MeasuredRpyDeg(d, s);
                                 for (int k = 0; k < 3; ++k) o[k] = a[k];
                               });
                             })
      .def_property_readonly("quat",
                             [](const Dataset& d) {
                               return PerSample(d, 4, [&d](const Sample& s, double* o) {
                                 const Eigen::Vector4d q = MeasuredQuat(d, s);
                                 for (int k = 0; k < 4; ++k) o[k] = q[k];
                               });
                             })
      .def_property_readonly("tension_kN",
                             [](const Dataset& d) {
                               return PerSample(d, kNumCables, [](const Sample& s, double* o) {
                                 for (int i = 0; i < kNumCables; ++i)
                                   o[i] = s.tension_n[i] / kNPerKn;
                               });
                             })
      .def_property_readonly("planned_rpy_deg",
                             [](const Dataset& d) -> py::object {
                               if (!d.has_planned_attitude) return py::none();
                               return PerSample(d, 3, [](const Sample& s, double* o) {
                                 for (int k = 0; k < 3; ++k) o[k] = s.planned_rpy_deg[k];
                               });
                             })
      .def_readonly("joint_columns", &Dataset::joint_columns,
                    "The moving parts' joint columns read (a model's, read_dataset(model=...)); "
                    "empty without.")
      .def_property_readonly("joints",
                             [](const Dataset& d) -> py::object {
                               const int n = static_cast<int>(d.joint_columns.size());
                               if (n == 0) return py::none();
                               return PerSample(d, n, [n](const Sample& s, double* o) {
                                 for (int j = 0; j < n; ++j) o[j] = s.joint[j];
                               });
                             },
                             "Joint values (n, J) in joint_columns order and their units (deg, "
                             "m); None without joint columns.")
      .def_property_readonly("s0_m",
                             [](const Dataset& d) -> py::object {
                               if (!d.has_unstretched_lengths) return py::none();
                               return PerSample(d, kNumCables, [](const Sample& s, double* o) {
                                 for (int i = 0; i < kNumCables; ++i)
                                   o[i] = s.unstretched_length_m[i];
                               });
                             })
      .def(
          "save",
          [](const Dataset& d, const std::string& path, const std::string& header_comment) {
            CheckPath(path, "dataset");
            std::string error;
            if (!WriteDataset(path, d, header_comment, &error)) throw InputError(error);
          },
          py::arg("path"), py::arg("header_comment") = "",
          "Writes the dataset file (atomically); read_dataset reads it back exactly.")
      .def("__repr__", [](const Dataset& d) {
        return "<fastcal.Dataset: " + std::to_string(d.samples.size()) + " samples from " +
               (d.path.empty() ? std::string("memory") : d.path) + ">";
      });
}

// simulate(truth, positions, attitude kind and values, options) -> (dataset, truth used,
// summary dict); the simulation runs without the GIL.
py::tuple SimulateFromArrays(const CableRobot& truth_argument, const DoubleArray& positions_m,
                             const std::string& attitude_kind, const DoubleArray& attitude,
                             const py::dict& options) {
  // A copy before the GIL is released (issue 29: another thread may change the model).
  const CableRobot truth = truth_argument;
  ValidateModel(truth);
  const SimulationOptions o = MakeSimulationOptions(options);
  const std::vector<Pose> planned = PosesFromArrays(positions_m, attitude_kind, attitude);
  Dataset data;
  CableRobot truth_used;
  SimulationSummary summary;
  std::string error;
  bool ok = false;
  {
    py::gil_scoped_release release;
    ok = Simulate(truth, planned, o, &data, &truth_used, &summary, &error);
  }
  if (!ok) throw InputError(error);
  return py::make_tuple(data, truth_used, SummaryDict(summary));
}

// A dataset from text the module wrote (a spreadsheet's rows, a DataFrame), read as a
// file is: ParseDataset with the map (if any).
Dataset ParseDatasetOrThrow(const std::string& text, const std::string& source_name,
                            bool skip_invalid_rows, const std::string& map_text,
                            const std::string& map_source, bool header_first,
                            const std::vector<std::string>& joint_columns) {
  DatasetReadOptions options;
  options.joint_columns = joint_columns;
  options.skip_invalid_rows = skip_invalid_rows;
  options.columns = MapOrThrow(map_text, map_source, true, header_first);
  Dataset data;
  std::string error;
  bool ok = false;
  {
    py::gil_scoped_release release;
    ok = ParseDataset(text, source_name, options, &data, &error);
  }
  if (!header_first) {
    if (!ok) throw InputError(error);
    return data;
  }
  // Arrays and DataFrames: rows numbered from 1 after the names, not lines.
  const auto rows = [&source_name](const std::string& message) {
    const std::string prefix = source_name + ":";
    if (message.compare(0, prefix.size(), prefix) != 0) return message;
    size_t end = prefix.size();
    int line = 0;
    while (end < message.size() && message[end] >= '0' && message[end] <= '9') {
      line = line * 10 + (message[end++] - '0');
    }
    if (end == prefix.size()) return message;
    return source_name + (line <= 1 ? ", columns" : ", row " + std::to_string(line - 1)) +
           message.substr(end);
  };
  if (!ok) throw InputError(rows(error));
  for (Sample& s : data.samples) s.line -= 1;
  for (std::string& why : data.skipped) why = rows(why);
  return data;
}

// The canonical CSV text of columns of numbers (`names`, values (n, k), each with the
// fewest digits that read back to the same double) and optional session labels per
// row, for Dataset.from_arrays: read by ParseDataset, so checked as a file is.
std::string CanonicalText(const std::vector<std::string>& names, const DoubleArray& values,
                          const std::vector<std::string>& sessions) {
  const auto v = values.unchecked<2>();
  const py::ssize_t n = v.shape(0), k = v.shape(1);
  if (k != static_cast<py::ssize_t>(names.size())) {
    throw InputError("from_arrays: " + std::to_string(k) + " columns of values for " +
                     std::to_string(names.size()) + " names");
  }
  if (!sessions.empty() && static_cast<py::ssize_t>(sessions.size()) != n) {
    throw InputError("from_arrays: session has " + std::to_string(sessions.size()) +
                     " labels for " + std::to_string(n) + " rows");
  }
  std::string text;
  for (size_t c = 0; c < names.size(); ++c) text += (c ? "," : "") + names[c];
  if (!sessions.empty()) text += ",session";
  text += "\n";
  text.reserve(text.size() + static_cast<size_t>(n * k) * 20);
  char buffer[64];
  for (py::ssize_t r = 0; r < n; ++r) {
    for (py::ssize_t c = 0; c < k; ++c) {
      if (c > 0) text += ',';
      const double x = v(r, c);
      if (std::isfinite(x)) {
        const auto result = std::to_chars(buffer, buffer + sizeof(buffer), x);
        text.append(buffer, result.ptr);
      } else {
        text += std::isnan(x) ? "nan" : x > 0 ? "inf" : "-inf";
      }
    }
    if (!sessions.empty()) text += "," + sessions[static_cast<size_t>(r)];
    text += '\n';
  }
  return text;
}

}  // namespace

void BindData(py::module_& m) {
  BindDatasetClass(m);
  m.def("read_dataset", &ReadDatasetOrThrow, py::arg("paths"), py::arg("skip_invalid_rows"),
        py::arg("map_text") = "", py::arg("map_source") = "",
        py::arg("joint_columns") = std::vector<std::string>());
  m.def("parse_dataset", &ParseDatasetOrThrow, py::arg("text"), py::arg("source_name"),
        py::arg("skip_invalid_rows"), py::arg("map_text"), py::arg("map_source"),
        py::arg("header_first"), py::arg("joint_columns") = std::vector<std::string>());
  m.def("canonical_text", &CanonicalText);
  m.def("column_map_decimal", [](const std::string& map_text, const std::string& map_source) {
    return std::string(1, MapOrThrow(map_text, map_source, false, false)->decimal);
  });
  m.def("simulate", &SimulateFromArrays);
}

}  // namespace fastcal::python
