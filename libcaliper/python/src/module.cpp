// The Python module `caliper` (its native part, `caliper._caliper`): libsmpl and libcaliper for
// Python with pybind11. The pure-Python part (libcaliper/python/caliper/) adds open_model(),
// the assets lookup and `python3 -m caliper`. Documentation: docs/library.md.
//
// Sections: 1. errors  2. arrays (numpy views of model data, no copies)  3. model
// 4. regressors and mappings  5. create  6. measure  7. evaluate (batch)  8. export
// 9. C++ baselines for the benchmarks  10. module
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstdint>
#include <exception>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "caliper/avatar.hpp"
#include "caliper/cpu_time.hpp"
#include "caliper/errors.hpp"
#include "caliper/inputs.hpp"
#include "caliper/json.hpp"
#include "caliper/mapping.hpp"
#include "caliper/measurements.hpp"
#include "caliper/plausibility.hpp"
#include "caliper/population.hpp"
#include "caliper/regressor.hpp"
#include "evaluate_many.hpp"
#include "smpl/body_model.hpp"
#include "smpl/evaluate.hpp"
#include "smpl/export.hpp"
#include "smpl/gltf.hpp"
#include "smpl/io.hpp"
#include "smpl/text.hpp"

#ifndef CALIPER_VERSION
#define CALIPER_VERSION "0.0.0"
#endif

namespace py = pybind11;

namespace {

using ModelPtr = std::shared_ptr<smpl::BodyModel>;

// ---------------------------------------------------------------------------------------------
// 1. Errors: every C++ exception becomes a Python exception carrying the C++ message.
// ---------------------------------------------------------------------------------------------

struct PyErrors {
  PyObject* error = nullptr;           // caliper.Error(Exception): base of all
  PyObject* model_error = nullptr;     // smpl::ModelError: file and format problems
  PyObject* invalid_input = nullptr;   // caliper::InvalidInputError, std::invalid_argument
  PyObject* landmark = nullptr;        // caliper::LandmarkError
  PyObject* model_mismatch = nullptr;  // caliper::ModelMismatchError
  PyObject* json = nullptr;            // caliper::JsonError
};
PyErrors g_errors;

PyObject* new_error(py::module_& m, const char* name, const char* doc, PyObject* bases) {
  const std::string full = std::string("caliper.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(full.c_str(), doc, bases, nullptr);
  if (!type) throw py::error_already_set();
  m.add_object(name, py::handle(type));
  return type;
}

void register_errors(py::module_& m) {
  g_errors.error = new_error(m, "Error", "Base class of every error the caliper module raises.",
                             PyExc_Exception);
  auto two = [](PyObject* a, PyObject* b) {
    return py::make_tuple(py::handle(a), py::handle(b)).release().ptr();
  };
  g_errors.model_error = new_error(
      m, "ModelError",
      "A model or avatar file could not be read or written: the message names the file, the key, "
      "the expected and the actual shape.",
      two(g_errors.error, PyExc_OSError));
  g_errors.invalid_input = new_error(
      m, "InvalidInputError",
      "An unusable value: NaN, a missing unit, an implausible measurement, a wrong array shape, "
      "an unknown measurement id or regressor.",
      two(g_errors.error, PyExc_ValueError));
  g_errors.landmark =
      new_error(m, "LandmarkError",
                "A measurement needs a landmark that the model does not define.", g_errors.error);
  g_errors.model_mismatch = new_error(
      m, "ModelMismatchError",
      "Regressors or a mapping that belong to another model, or a malformed regressor file.",
      g_errors.error);
  g_errors.json =
      new_error(m, "JsonError", "A malformed JSON document (regressors, mapping).", g_errors.error);
  // NOLINTNEXTLINE(performance-unnecessary-value-param): pybind11 takes void(*)(exception_ptr)
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const smpl::ModelError& e) {
      PyErr_SetString(g_errors.model_error, e.what());
    } catch (const caliper::InvalidInputError& e) {
      PyErr_SetString(g_errors.invalid_input, e.what());
    } catch (const caliper::LandmarkError& e) {
      PyErr_SetString(g_errors.landmark, e.what());
    } catch (const caliper::ModelMismatchError& e) {
      PyErr_SetString(g_errors.model_mismatch, e.what());
    } catch (const caliper::CaliperError& e) {
      PyErr_SetString(g_errors.error, e.what());
    } catch (const caliper::JsonError& e) {
      PyErr_SetString(g_errors.json, e.what());
    } catch (const std::invalid_argument& e) {
      PyErr_SetString(g_errors.invalid_input, e.what());
    }
    // Anything else falls through to pybind11's own translators (RuntimeError, MemoryError...).
  });
}

[[noreturn]] void invalid(const std::string& message) {
  throw caliper::InvalidInputError(message);
}

// ---------------------------------------------------------------------------------------------
// 2. Arrays: read-only numpy views of model data (the model object stays alive as their base).
// ---------------------------------------------------------------------------------------------

template <class T>
py::array readonly_view(const T* data, std::vector<py::ssize_t> shape,
                        std::vector<py::ssize_t> strides, py::handle base) {
  py::array a(py::dtype::of<T>(), std::move(shape), std::move(strides), data, base);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

/// A row-major Eigen matrix as a (rows, cols) view.
template <class M>
py::array matrix_view(const M& mat, py::handle base) {
  using T = typename M::Scalar;
  static_assert(M::IsRowMajor, "row-major only");
  const auto s = static_cast<py::ssize_t>(sizeof(T));
  return readonly_view<T>(mat.data(), {mat.rows(), mat.cols()}, {mat.cols() * s, s}, base);
}

/// Blend shapes kept as a (3V, N) column-major matrix (shapedirs, posedirs) as a (V, 3, N) view
/// (V, 3, 0 for a model without pose blend shapes, whose posedirs is empty).
py::array blend_shapes_view(const Eigen::MatrixXd& dirs, py::ssize_t v, py::handle base) {
  const py::ssize_t n = dirs.cols(), s = sizeof(double);
  return readonly_view<double>(dirs.data(), {v, 3, n}, {3 * s, s, 3 * v * s}, base);
}

/// A freshly allocated (rows, cols) float64 copy of a row-major matrix.
template <class M>
py::array_t<double> matrix_copy(const M& mat) {
  py::array_t<double> out(
      {static_cast<py::ssize_t>(mat.rows()), static_cast<py::ssize_t>(mat.cols())});
  auto r = out.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < mat.rows(); ++i)
    for (Eigen::Index j = 0; j < mat.cols(); ++j) r(i, j) = static_cast<double>(mat(i, j));
  return out;
}

py::array_t<double> vector_copy(const Eigen::VectorXd& v) {
  py::array_t<double> out(static_cast<py::ssize_t>(v.size()));
  std::copy(v.data(), v.data() + v.size(), out.mutable_data());
  return out;
}

/// A float vector from any 1-D sequence or array (converted to float64); `what` names it.
Eigen::VectorXd to_vector(const py::handle& obj, const char* what) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  if (!a) invalid(std::string(what) + ": expected a sequence of numbers");
  if (a.ndim() != 1)
    invalid(std::string(what) + ": expected a 1-D array, got " + std::to_string(a.ndim()) +
            " dimensions");
  return Eigen::Map<const Eigen::VectorXd>(a.data(), a.shape(0));
}

/// V x 3 vertices from an array of shape (V, 3) (any float dtype; copied to float64).
smpl::Vertices to_vertices(const py::handle& obj, const char* what) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  if (!a || a.ndim() != 2 || a.shape(1) != 3)
    invalid(std::string(what) + ": expected an array of shape (V, 3)");
  return Eigen::Map<const smpl::Vertices>(a.data(), a.shape(0), 3);
}

smpl::Faces to_faces(const py::handle& obj, const char* what) {
  const auto a = py::array_t<std::int32_t, py::array::c_style | py::array::forcecast>::ensure(obj);
  if (!a || a.ndim() != 2 || a.shape(1) != 3)
    invalid(std::string(what) + ": expected an integer array of shape (F, 3)");
  return Eigen::Map<const smpl::Faces>(a.data(), a.shape(0), 3);
}

// ---------------------------------------------------------------------------------------------
// 3. Model
// ---------------------------------------------------------------------------------------------

ModelPtr load_model(const std::string& path, int num_betas, bool pose_blend_shapes) {
  smpl::LoadOptions o;
  o.num_betas = num_betas;
  o.load_pose_blend_shapes = pose_blend_shapes;
  py::gil_scoped_release release;
  return std::make_shared<smpl::BodyModel>(smpl::load_model(path, o));
}

const smpl::BodyModel& model_of(const py::handle& self) {
  return *self.cast<ModelPtr>();
}

// ---------------------------------------------------------------------------------------------
// 4. Regressors and mappings
// ---------------------------------------------------------------------------------------------

using RegressorsPtr = std::shared_ptr<caliper::RegressorSet>;

RegressorsPtr train(const ModelPtr& model, int num_betas, bool gaussian, double corner_sd,
                    int gaussian_count, std::uint64_t seed, bool noise_aware,
                    const std::optional<caliper::NoiseLevels>& noise) {
  caliper::TrainOptions o;
  o.num_betas = num_betas;
  o.gaussian = gaussian;
  o.corner_sd = corner_sd;
  o.gaussian_count = gaussian_count;
  o.seed = seed;
  o.noise_aware = noise_aware;
  if (noise) o.noise = *noise;
  py::gil_scoped_release release;
  return std::make_shared<caliper::RegressorSet>(caliper::train_regressors(*model, o));
}

RegressorsPtr load_regressors(const std::string& path, const ModelPtr& model) {
  py::gil_scoped_release release;
  auto set = std::make_shared<caliper::RegressorSet>(caliper::RegressorSet::load(path));
  if (model) set->check(*model);
  return set;
}

std::shared_ptr<caliper::MeasurementMapping> load_mapping(const std::string& path) {
  const std::string ext = path.size() >= 4 ? path.substr(path.size() - 4) : "";
  py::gil_scoped_release release;
  if (ext == ".csv" || ext == ".CSV") {
    return std::make_shared<caliper::MeasurementMapping>(
        caliper::MeasurementMapping::fit(caliper::read_paired_csv(path)));
  }
  return std::make_shared<caliper::MeasurementMapping>(caliper::MeasurementMapping::load(path));
}

/// Measurement id of a Python name: the ids themselves, plus the CLI's short names.
std::string measurement_id(const std::string& name) {
  if (name == "arm_span") return "arm_span_fingertips";
  if (name == "inseam") return "inseam_height";
  return name;
}

/// A value given as a number (SI: metres, kilograms) or as text with its unit ("168cm").
double measurement_value(const std::string& id, const py::handle& value) {
  if (py::isinstance<py::str>(value)) {
    const std::string text = value.cast<std::string>();
    return id == "weight" ? caliper::parse_mass(text, id) : caliper::parse_length(text, id);
  }
  if (py::isinstance<py::bool_>(value)) invalid(id + ": expected a number or a text with a unit");
  try {
    return value.cast<double>();
  } catch (const py::cast_error&) {
    invalid(id +
            ": expected a number (metres, kilograms) or a text with a unit such as '168cm', "
            "got " +
            std::string(py::str(py::type::handle_of(value).attr("__name__"))));
  }
}

caliper::MeasurementMap measurement_map(const py::handle& dict, const char* what) {
  caliper::MeasurementMap out;
  if (dict.is_none()) return out;
  if (!py::isinstance<py::dict>(dict)) invalid(std::string(what) + ": expected a dict");
  for (const auto& [k, v] : dict.cast<py::dict>()) {
    const std::string id = measurement_id(py::str(k).cast<std::string>());
    out[id] = measurement_value(id, v);
  }
  return out;
}

caliper::NoiseLevels noise_levels(const py::handle& dict) {
  caliper::NoiseLevels out;
  if (dict.is_none()) return out;
  if (!py::isinstance<py::dict>(dict)) invalid("noise: expected a dict of standard deviations");
  for (const auto& [k, v] : dict.cast<py::dict>()) {
    const std::string id = measurement_id(py::str(k).cast<std::string>());
    out[id] = measurement_value(id, v);
  }
  return out;
}

py::dict to_dict(const caliper::MeasurementMap& m) {
  py::dict d;
  for (const auto& [k, v] : m) d[py::str(k)] = v;
  return d;
}

// ---------------------------------------------------------------------------------------------
// 5. create
// ---------------------------------------------------------------------------------------------

/// An avatar and what made it.
struct PyAvatar {
  caliper::Avatar avatar;
  ModelPtr model;
  std::string regressor;
};

struct CreateRequest {
  caliper::MeasurementMap inputs;
  std::string regressor;
  bool exact_inputs = false;
  bool shape_curve = true;
  bool force = false;
  bool circumferences = true;
  caliper::NoiseLevels noise;
  std::shared_ptr<caliper::MeasurementMapping> mapping;
  std::optional<caliper::ShapePrior> prior;  ///< population=: the noise-aware regressor's prior
};

/// The C++ work of create() (also timed alone by the benchmark baseline).
PyAvatar create_avatar(const ModelPtr& model, const caliper::RegressorSet& regressors,
                       const CreateRequest& r) {
  caliper::AvatarOptions o;
  o.exact_inputs = r.exact_inputs;
  o.shape_curve = r.shape_curve;
  o.mapping = r.mapping.get();
  o.circumferences = r.circumferences;
  o.refuse_invalid = !r.force;
  o.prior = r.prior ? &*r.prior : nullptr;
  PyAvatar out;
  out.model = model;
  out.regressor = r.regressor;
  if (r.regressor == "noise-aware") {
    if (!regressors.noise_aware)
      invalid("the regressor set has no noise-aware regressor; train with noise_aware=True");
    out.avatar = caliper::create_avatar(*model, *regressors.noise_aware, r.inputs, o, r.noise);
    return out;
  }
  if (!r.noise.empty()) invalid("noise levels apply to the noise-aware regressor only");
  const caliper::LinearRegressor* lin = regressors.find(r.regressor);
  if (!lin) invalid("the regressor set has no regressor " + r.regressor);
  out.avatar = caliper::create_avatar(*model, *lin, r.inputs, o);
  return out;
}

CreateRequest make_request(const py::object& measurements, const py::dict& named,
                           const py::object& regressor, bool exact_inputs, bool force,
                           bool circumferences, const py::object& noise,
                           std::shared_ptr<caliper::MeasurementMapping> mapping) {
  CreateRequest r;
  r.inputs = measurement_map(measurements, "measurements");
  for (const auto& [k, v] : named) {
    if (v.is_none()) continue;
    const std::string id = measurement_id(k.cast<std::string>());
    if (r.inputs.count(id)) invalid(id + " is given twice (in measurements and as a keyword)");
    r.inputs[id] = measurement_value(id, v);
  }
  if (r.inputs.empty())
    invalid(
        "no measurements given; give at least height (and usually weight), e.g. "
        "height='168cm', weight='62kg'");
  r.regressor = regressor.is_none()
                    ? caliper::default_regressor(r.inputs)
                    : caliper::normalise_regressor_name(regressor.cast<std::string>(), "regressor");
  if (r.regressor != "noise-aware") {
    std::string missing;
    for (const auto& id : caliper::regressor_inputs(*caliper::parse_regressor_kind(r.regressor)))
      if (!r.inputs.count(id)) missing += (missing.empty() ? "" : ", ") + id;
    if (!missing.empty())
      invalid("regressor " + r.regressor + " needs " + missing +
              " (or choose regressor='noise-aware', which takes any subset)");
  }
  r.exact_inputs = exact_inputs;
  r.force = force;
  r.circumferences = circumferences;
  r.noise = noise_levels(noise);
  r.mapping = std::move(mapping);
  return r;
}

// ---------------------------------------------------------------------------------------------
// 6. measure
// ---------------------------------------------------------------------------------------------

caliper::MeasurementMap measure(const ModelPtr& model, const py::object& vertices,
                                const py::object& betas, bool circumferences, bool convex_hull) {
  if (vertices.is_none() == betas.is_none())
    invalid("measure: give either vertices (V x 3, metres, rest pose) or betas, not both");
  caliper::MeasureOptions o;
  o.circumferences = circumferences;
  o.convex_hull = convex_hull;
  if (!betas.is_none()) {
    const Eigen::VectorXd b = to_vector(betas, "betas");
    py::gil_scoped_release release;
    return caliper::measure_all(*model, caliper::shaped_vertices(*model, b), o);
  }
  const smpl::Vertices v = to_vertices(vertices, "vertices");
  py::gil_scoped_release release;
  return caliper::measure_all(*model, v, o);
}

// ---------------------------------------------------------------------------------------------
// 7. evaluate: a batch of betas / poses in, vertices (and joints) out.
// ---------------------------------------------------------------------------------------------

using InArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// Checks the arrays of evaluate() and returns the batch size.
py::ssize_t batch_size(const smpl::BodyModel& model, const InArray& betas, const InArray* poses,
                       const InArray* translations, bool& single) {
  if (betas.ndim() != 1 && betas.ndim() != 2)
    invalid("betas: expected shape (B,) or (N, B), got " + std::to_string(betas.ndim()) +
            " dimensions");
  single = betas.ndim() == 1;
  const py::ssize_t n = single ? 1 : betas.shape(0);
  const py::ssize_t nb = betas.shape(betas.ndim() - 1);
  if (nb > model.num_betas())
    invalid("betas: " + std::to_string(nb) + " values per body, but the model has " +
            std::to_string(model.num_betas()) + " shape components");
  const py::ssize_t k3 = 3 * py::ssize_t{model.num_joints()};
  if (poses) {
    const bool ok = single
                        ? (poses->ndim() == 1 && poses->shape(0) == k3) ||
                              (poses->ndim() == 2 && poses->shape(0) == model.num_joints() &&
                               poses->shape(1) == 3)
                        : (poses->ndim() == 2 && poses->shape(0) == n && poses->shape(1) == k3) ||
                              (poses->ndim() == 3 && poses->shape(0) == n &&
                               poses->shape(1) == model.num_joints() && poses->shape(2) == 3);
    if (!ok)
      invalid(
          "poses: expected shape " +
          (single
               ? "(" + std::to_string(k3) + ",) or (" + std::to_string(model.num_joints()) + ", 3)"
               : "(" + std::to_string(n) + ", " + std::to_string(k3) + ") or (" +
                     std::to_string(n) + ", " + std::to_string(model.num_joints()) + ", 3)") +
          " (axis-angle per joint, joint 0 = global orientation, radians)");
  }
  if (translations) {
    const bool ok = single ? translations->ndim() == 1 && translations->shape(0) == 3
                           : translations->ndim() == 2 && translations->shape(0) == n &&
                                 translations->shape(1) == 3;
    if (!ok)
      invalid(single ? "translations: expected shape (3,)" : "translations: expected shape (N, 3)");
  }
  return n;
}

template <class Out>
py::object evaluate_typed(const ModelPtr& model, const InArray& betas, const InArray* poses,
                          const InArray* translations, bool joints, py::ssize_t n, bool single) {
  const py::ssize_t v = model->num_vertices(), k = model->num_joints();
  // The vertex array (N V 3 values: 1.2 GB for 4,096 bodies of the open models) is allocated
  // with new[] as a C++ caller's would be, and owned by the numpy array through a capsule.
  // numpy's own allocator asks for transparent huge pages (madvise), which on a busy machine with
  // the kernel's defrag=madvise setting can stall in direct compaction (docs/performance.md).
  const size_t count = static_cast<size_t>(n) * static_cast<size_t>(v) * 3;
  Out* buffer = new Out[count];
  py::capsule owner(buffer, [](void* p) { delete[] static_cast<Out*>(p); });
  py::array_t<Out> verts = single ? py::array_t<Out>({v, py::ssize_t{3}}, buffer, owner)
                                  : py::array_t<Out>({n, v, py::ssize_t{3}}, buffer, owner);
  py::array_t<Out> jts;
  if (joints)
    jts = single ? py::array_t<Out>({k, py::ssize_t{3}}) : py::array_t<Out>({n, k, py::ssize_t{3}});
  caliper::python::BatchInput in;
  in.count = static_cast<int>(n);
  in.betas = betas.data();
  in.num_betas = static_cast<int>(betas.shape(betas.ndim() - 1));
  in.poses = poses ? poses->data() : nullptr;
  in.translations = translations ? translations->data() : nullptr;
  Out* vo = verts.mutable_data();
  Out* jo = joints ? jts.mutable_data() : nullptr;
  {
    py::gil_scoped_release release;
    caliper::python::evaluate_many(*model, in, vo, jo);
  }
  if (joints) return py::make_tuple(verts, jts);
  return std::move(verts);
}

py::object evaluate(const ModelPtr& model, const py::handle& betas_obj, const py::handle& poses_obj,
                    const py::handle& translations_obj, const py::handle& dtype, bool joints) {
  const InArray betas = InArray::ensure(betas_obj);
  if (!betas) invalid("betas: expected an array of numbers");
  std::optional<InArray> poses, translations;
  if (!poses_obj.is_none()) {
    poses = InArray::ensure(poses_obj);
    if (!*poses) invalid("poses: expected an array of numbers");
  }
  if (!translations_obj.is_none()) {
    translations = InArray::ensure(translations_obj);
    if (!*translations) invalid("translations: expected an array of numbers");
  }
  bool single = false;
  const py::ssize_t n = batch_size(*model, betas, poses ? &*poses : nullptr,
                                   translations ? &*translations : nullptr, single);
  const py::dtype dt = py::dtype::from_args(py::reinterpret_borrow<py::object>(dtype));
  if (dt.kind() == 'f' && dt.itemsize() == 8)
    return evaluate_typed<double>(model, betas, poses ? &*poses : nullptr,
                                  translations ? &*translations : nullptr, joints, n, single);
  if (dt.kind() == 'f' && dt.itemsize() == 4)
    return evaluate_typed<float>(model, betas, poses ? &*poses : nullptr,
                                 translations ? &*translations : nullptr, joints, n, single);
  invalid("dtype: expected numpy.float64 or numpy.float32, got " +
          py::repr(dt).cast<std::string>());
}

// ---------------------------------------------------------------------------------------------
// 8. Export
// ---------------------------------------------------------------------------------------------

std::string lower_extension(const std::string& path) {
  const auto slash = path.find_last_of('/');
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return smpl::to_lower(path.substr(dot));
}

/// The asset.extras `caliper create` writes (so that `caliper measure` reads the avatar back).
std::map<std::string, std::string> default_extras(const PyAvatar& a) {
  std::map<std::string, std::string> extras;
  extras["generator"] = std::string("caliper ") + CALIPER_VERSION + " (python)";
  extras["regressor"] = a.regressor;
  caliper::Json betas = caliper::Json::array();
  for (Eigen::Index i = 0; i < a.avatar.betas.size(); ++i) betas.push_back(a.avatar.betas[i]);
  extras["betas"] = betas.dump();
  caliper::Json m = caliper::Json::object();
  for (const auto& [k, v] : a.avatar.achieved) m.set(k, v);
  extras["measurements"] = m.dump();
  extras["model"] = a.model->meta.name;
  return extras;
}

void save_avatar(const PyAvatar& a, const std::string& path,
                 const std::optional<std::map<std::string, std::string>>& extras,
                 bool pose_correctives) {
  const std::string ext = lower_extension(path);
  py::gil_scoped_release release;
  if (ext == ".glb" || ext == ".gltf") {
    smpl::GltfOptions o;
    o.extras = default_extras(a);
    if (extras)
      for (const auto& [k, v] : *extras) o.extras[k] = v;
    o.pose_correctives = pose_correctives;
    smpl::write_gltf(path, *a.model, a.avatar.betas, o);
    return;
  }
  if (ext != ".obj" && ext != ".ply")
    invalid(path + ": unknown avatar extension '" + ext + "' (use .glb, .gltf, .obj or .ply)");
  smpl::Vertices v = a.avatar.vertices;
  if (v.rows() > 0) v.col(1).array() -= v.col(1).minCoeff();  // stand on the floor, as the CLI
  if (ext == ".obj")
    smpl::write_obj(path, v, a.model->faces);
  else
    smpl::write_ply(path, v, a.model->faces);
}

smpl::GltfOptions gltf_options(bool stand_on_floor, bool pose_correctives, const std::string& name,
                               const std::optional<std::map<std::string, std::string>>& extras) {
  smpl::GltfOptions o;
  o.stand_on_floor = stand_on_floor;
  o.pose_correctives = pose_correctives;
  o.name = name;
  if (extras) o.extras = *extras;
  return o;
}

py::dict read_gltf(const std::string& path) {
  smpl::GltfAvatar a;
  {
    py::gil_scoped_release release;
    a = smpl::read_gltf(path);
  }
  py::dict d;
  d["vertices"] = matrix_copy(a.vertices);
  py::array_t<std::int32_t> faces({static_cast<py::ssize_t>(a.faces.rows()), py::ssize_t{3}});
  std::copy(a.faces.data(), a.faces.data() + a.faces.size(), faces.mutable_data());
  d["faces"] = faces;
  d["joints"] = matrix_copy(a.joints);
  d["joint_names"] = a.joint_names;
  d["parents"] = a.parents;
  d["generator"] = a.generator;
  d["extras"] = a.extras;
  d["warnings"] = a.warnings;
  return d;
}

// ---------------------------------------------------------------------------------------------
// 9. C++ baselines for the benchmarks (tests/bench/bench_python.py): the same C++ work as
//    create() and evaluate(), timed inside C++ (no Python in the loop) in thread CPU time,
//    median of `repeats`.
// ---------------------------------------------------------------------------------------------

double median(std::vector<double> t) {
  std::sort(t.begin(), t.end());
  return t.empty() ? 0.0 : t[t.size() / 2];
}

double time_create_cpp(const ModelPtr& model, const RegressorsPtr& regressors,
                       const py::dict& measurements, const py::object& regressor, int repeats) {
  const CreateRequest r =
      make_request(measurements, py::dict(), regressor, false, false, true, py::none(), nullptr);
  py::gil_scoped_release release;
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i) {
    const double t0 = caliper::thread_cpu_seconds();
    {  // the avatar is freed inside the timed section, as a Python caller's is
      const PyAvatar a = create_avatar(model, *regressors, r);
      if (a.avatar.betas.size() == 0) throw std::runtime_error("no betas");
    }
    t.push_back(caliper::thread_cpu_seconds() - t0);
  }
  return median(t);
}

/// The C++ loop of evaluate() with `Out` (double or float) output, timed as time_evaluate_cpp.
template <class Out>
double time_evaluate_typed(const smpl::BodyModel& model, const caliper::python::BatchInput& in,
                           size_t size, int repeats) {
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i) {
    // A fresh uninitialised output per call, as evaluate() allocates its numpy array: a C++
    // caller also needs somewhere to put N x V x 3 results.
    const double t0 = caliper::thread_cpu_seconds();
    {
      std::unique_ptr<Out[]> out(new Out[size]);  // freed inside the timed section
      caliper::python::evaluate_many(model, in, out.get(), static_cast<Out*>(nullptr));
    }
    t.push_back(caliper::thread_cpu_seconds() - t0);
  }
  return median(t);
}

double time_evaluate_cpp(const ModelPtr& model, const InArray& betas, const py::object& poses_obj,
                         bool float32, int repeats) {
  std::optional<InArray> poses;
  if (!poses_obj.is_none()) poses = InArray::ensure(poses_obj);
  bool single = false;
  const py::ssize_t n = batch_size(*model, betas, poses ? &*poses : nullptr, nullptr, single);
  caliper::python::BatchInput in;
  in.count = static_cast<int>(n);
  in.betas = betas.data();
  in.num_betas = static_cast<int>(betas.shape(betas.ndim() - 1));
  in.poses = poses ? poses->data() : nullptr;
  const size_t size = static_cast<size_t>(n) * static_cast<size_t>(model->num_vertices()) * 3;
  py::gil_scoped_release release;
  return float32 ? time_evaluate_typed<float>(*model, in, size, repeats)
                 : time_evaluate_typed<double>(*model, in, size, repeats);
}

}  // namespace

namespace {

// BodyModel: loading, arrays, evaluation.
void bind_model(py::module_& m) {
  // --- model ---
  py::class_<smpl::BodyModel, ModelPtr>(
      m, "BodyModel",
      "An SMPL-family body model (SMPL, SMPL-H, SMPL-X, MANO or the open caliper models), "
      "immutable. Array attributes are read-only numpy views of the model's own memory (no "
      "copies) unless noted. Load with load_model() or open_model().")
      .def_property_readonly(
          "v_template",
          [](const py::object& self) { return matrix_view(model_of(self).v_template, self); },
          "(V, 3) float64 template vertices (rest T-pose, mean shape), metres. smplx: v_template.")
      .def_property_readonly(
          "faces", [](const py::object& self) { return matrix_view(model_of(self).faces, self); },
          "(F, 3) int32 triangles (0-based, counter-clockwise from outside). smplx: faces.")
      .def_property_readonly(
          "shapedirs",
          [](const py::object& self) {
            const auto& md = model_of(self);
            return blend_shapes_view(md.shapedirs, md.num_vertices(), self);
          },
          "(V, 3, B) float64 shape blend shapes (one standard deviation per component), metres. "
          "smplx: shapedirs (same layout).")
      .def_property_readonly(
          "posedirs",
          [](const py::object& self) {
            const auto& md = model_of(self);
            return blend_shapes_view(md.posedirs, md.num_vertices(), self);
          },
          "(V, 3, P) float64 pose blend shapes, P = 9 (K - 1) (or 0). smplx keeps "
          "posedirs.reshape(-1, P).T, i.e. (P, 3V).")
      .def_property_readonly(
          "j_regressor",
          [](const py::object& self) {
            return matrix_copy(Eigen::MatrixXd(model_of(self).j_regressor));
          },
          "(K, V) float64 joint regressor (a dense copy of the sparse matrix). smplx: "
          "J_regressor.")
      .def_property_readonly(
          "weights",
          [](const py::object& self) {
            using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
            return matrix_copy(RowMajor(model_of(self).weights));
          },
          "(V, K) float64 skinning weights (a dense copy). smplx: lbs_weights.")
      .def_property_readonly(
          "parents", [](const smpl::BodyModel& md) { return md.parents; },
          "K parent joint indices, parents[0] == -1. smplx: parents.")
      .def_property_readonly(
          "joint_names", [](const smpl::BodyModel& md) { return md.joint_names; },
          "K joint names ('pelvis', 'left_hip', ...).")
      .def_property_readonly(
          "landmarks", [](const smpl::BodyModel& md) { return md.landmarks; },
          "The model's own landmark table: name -> vertex ids (may be empty; SMPL topology uses "
          "a built-in table).")
      .def_property_readonly(
          "name", [](const smpl::BodyModel& md) { return md.meta.name; }, "Model name.")
      .def_property_readonly(
          "gender", [](const smpl::BodyModel& md) { return md.meta.gender; },
          "'female', 'male', 'neutral' or '' when unknown (picks the weight formula).")
      .def_property_readonly(
          "source", [](const smpl::BodyModel& md) { return md.meta.source; },
          "The file the model was loaded from.")
      .def_property_readonly("num_vertices", &smpl::BodyModel::num_vertices, "V.")
      .def_property_readonly("num_faces", &smpl::BodyModel::num_faces, "F.")
      .def_property_readonly("num_joints", &smpl::BodyModel::num_joints, "K.")
      .def_property_readonly("num_betas", &smpl::BodyModel::num_betas,
                             "B, the number of shape components.")
      .def_property_readonly("num_pose_features", &smpl::BodyModel::num_pose_features,
                             "P = 9 (K - 1), or 0 without pose blend shapes.")
      .def(
          "save",
          [](const smpl::BodyModel& md, const std::string& path, bool compress) {
            smpl::SaveOptions o;
            o.compress = compress;
            py::gil_scoped_release release;
            smpl::save_model(md, path, o);
          },
          py::arg("path"), py::arg("compress") = false,
          "Saves the model in the project's .npz format (SMPL keys plus landmarks, joint names, "
          "metadata; byte-for-byte deterministic). Raises ModelError when it cannot be written.")
      .def("__repr__", [](const smpl::BodyModel& md) {
        return "<caliper.BodyModel '" + md.meta.name + "' (" +
               (md.meta.gender.empty() ? "?" : md.meta.gender) + "), " +
               std::to_string(md.num_vertices()) + " vertices, " + std::to_string(md.num_joints()) +
               " joints, " + std::to_string(md.num_betas()) + " betas>";
      });

  m.def("load_model", &load_model, py::arg("path"), py::arg("num_betas") = -1,
        py::arg("pose_blend_shapes") = true,
        "Loads an SMPL-family model from .npz or .pkl (chosen by content; pickles through a "
        "restricted unpickler that never executes anything). num_betas: keep the first n shape "
        "components (-1: all). pose_blend_shapes=False skips posedirs (34 MB for SMPL). Raises "
        "ModelError naming the file and the problem.");
}

// The linear and noise-aware regressors, the regressor set, train_regressors and load_regressors.
void bind_regressors(py::module_& m) {
  // --- regressors ---
  py::class_<caliper::LinearRegressor>(
      m, "LinearRegressor",
      "One of the paper's regressors R2, R4, R5, R6: betas = A [features; 1] (features: the "
      "inputs in metres, weight as the cube root of its volume).")
      .def_property_readonly("name", &caliper::LinearRegressor::name, "'R2', 'R4', 'R5' or 'R6'.")
      .def_property_readonly("inputs", &caliper::LinearRegressor::inputs,
                             "Input measurement ids, in order.")
      .def_property_readonly(
          "coefficients",
          [](const caliper::LinearRegressor& r) {
            using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
            return matrix_copy(RowMajor(r.coefficients()));
          },
          "(k, inputs + 1) float64 matrix A (a copy); the last column is the intercept.")
      .def(
          "predict",
          [](const caliper::LinearRegressor& r, const py::dict& values) {
            return vector_copy(r.predict(measurement_map(values, "values")));
          },
          py::arg("values"),
          "Betas (k values) for a dict of inputs (numbers in metres / kg, or texts with units).");

  py::class_<caliper::NoiseAwareRegressor>(
      m, "NoiseAwareRegressor",
      "The Bayesian regressor: any subset of the six inputs gives a posterior mean and "
      "covariance of the betas (docs/regressors.md).")
      .def_property_readonly("inputs", &caliper::NoiseAwareRegressor::inputs,
                             "The inputs it can use.")
      .def_property_readonly("noise", &caliper::NoiseAwareRegressor::noise,
                             "Default noise SD per input (metres; weight in kg).")
      .def(
          "predict",
          [](const caliper::NoiseAwareRegressor& r, const py::dict& values,
             const py::object& noise) {
            const caliper::Posterior p =
                r.predict(measurement_map(values, "values"), noise_levels(noise));
            return py::make_tuple(
                vector_copy(p.mean),
                matrix_copy(Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>(
                    p.covariance)));
          },
          py::arg("values"), py::arg("noise") = py::none(),
          "(mean, covariance) of the betas for the given inputs; noise overrides the SD per "
          "input.");

  py::class_<caliper::RegressorSet, RegressorsPtr>(
      m, "Regressors",
      "The regressors of one model (R2, R4, R5, R6 and the noise-aware one), from "
      "train_regressors() or load_regressors().")
      .def_property_readonly(
          "names",
          [](const caliper::RegressorSet& s) {
            std::vector<std::string> n;
            for (const auto& r : s.linear) n.push_back(r.name());
            if (s.noise_aware) n.push_back("noise-aware");
            return n;
          },
          "Names of the regressors in the set.")
      .def(
          "linear",
          [](const caliper::RegressorSet& s, const std::string& name) {
            const caliper::LinearRegressor* r = s.find(name);
            if (!r) invalid("the regressor set has no regressor " + name);
            return *r;
          },
          py::arg("name"), "The linear regressor 'R2', 'R4', 'R5' or 'R6' (a copy).")
      .def_property_readonly(
          "noise_aware",
          [](const caliper::RegressorSet& s) -> std::optional<caliper::NoiseAwareRegressor> {
            return s.noise_aware;
          },
          "The noise-aware regressor (a copy), or None.")
      .def(
          "save",
          [](const caliper::RegressorSet& s, const std::string& path) {
            py::gil_scoped_release release;
            s.save(path);
          },
          py::arg("path"), "Writes the set as JSON (the format of `caliper train --save`).")
      .def(
          "check", [](const caliper::RegressorSet& s, const ModelPtr& md) { s.check(*md); },
          py::arg("model"), "Raises ModelMismatchError if a regressor does not belong to model.");

  m.def("train_regressors", &train, py::arg("model"), py::arg("num_betas") = 0,
        py::arg("gaussian") = false, py::arg("corner_sd") = 2.0, py::arg("gaussian_count") = 1024,
        py::arg("seed") = 1, py::arg("noise_aware") = true, py::arg("noise") = py::none(),
        "Trains R2, R4, R5, R6 (and the noise-aware regressor) for model, as the paper: bodies at "
        "the 2^k corners of betas in {-corner_sd, +corner_sd}^k (k = num_betas, default "
        "min(10, B)), or gaussian_count random bodies. noise: SD per input for the noise-aware "
        "regressor (default: the paper's self-measurement errors).");
  m.def("load_regressors", &load_regressors, py::arg("path"), py::arg("model") = nullptr,
        "Loads regressors saved by Regressors.save() or `caliper train --save`; with model, "
        "checks that they belong to it (ModelMismatchError).");
}

// MeasurementMapping and load_mapping.
void bind_mapping(py::module_& m) {
  py::class_<caliper::MeasurementMapping, std::shared_ptr<caliper::MeasurementMapping>>(
      m, "Mapping", "A real-to-virtual measurement mapping (virtual = a real + b per measurement).")
      .def(
          "apply",
          [](const caliper::MeasurementMapping& mp, const py::dict& values) {
            return to_dict(mp.apply(measurement_map(values, "values")));
          },
          py::arg("values"), "Maps a dict of measurements (unfitted ids pass unchanged).")
      .def_property_readonly(
          "measurements",
          [](const caliper::MeasurementMapping& mp) {
            std::vector<std::string> ids;
            for (const auto& [id, map] : mp.maps()) ids.push_back(id);
            return ids;
          },
          "The fitted measurement ids.");
  m.def("load_mapping", &load_mapping, py::arg("path"),
        "Loads a mapping: .json (from training) or a paired .csv (fitted now), as `caliper "
        "create --mapping`.");
  m.def(
      "hanging_arm_map",
      [](const ModelPtr& model, int bodies) {
        if (!model) throw caliper::InvalidInputError("hanging_arm_map: model is None");
        const caliper::LinearMap map = caliper::hanging_arm_map(*model, bodies);
        py::dict d;
        d["a"] = map.a;
        d["b"] = map.b;
        d["fit_rms"] = map.fit_rms;
        d["count"] = map.count;
        return d;
      },
      py::arg("model"), py::arg("bodies") = 200,
      "The model's map from an arm length taken on the hanging arm (acromion to wrist, as ANSUR "
      "II and a tape take it) to its arm_length (arm out sideways): arm_length = a * hanging + "
      "b, least squares over `bodies` of its bodies (caliper::hanging_arm_map). Returns a dict: "
      "a, b, fit_rms (metres), count.");
}

// Plausibility and Avatar.
void bind_avatar(py::module_& m) {
  // --- create ---
  py::class_<caliper::Plausibility>(m, "Plausibility",
                                    "How plausible a shape is under the prior betas ~ N(0, I).")
      .def_readonly("beyond_2sd", &caliper::Plausibility::beyond_2sd, "Indices with |beta| > 2.")
      .def_readonly("beyond_3sd", &caliper::Plausibility::beyond_3sd, "Indices with |beta| > 3.")
      .def_readonly("mahalanobis", &caliper::Plausibility::mahalanobis, "|beta|.")
      .def_readonly("dof", &caliper::Plausibility::dof, "Number of betas.")
      .def_readonly("cdf", &caliper::Plausibility::cdf, "P(chi^2_k <= |beta|^2).")
      .def_readonly("p_value", &caliper::Plausibility::p_value, "1 - cdf.")
      .def_readonly("plausible", &caliper::Plausibility::plausible,
                    "No component beyond 3 SD and p_value >= 0.001.")
      .def("__repr__", [](const caliper::Plausibility& p) {
        return std::string("<caliper.Plausibility plausible=") + (p.plausible ? "True" : "False") +
               " mahalanobis=" + std::to_string(p.mahalanobis) + ">";
      });

  py::class_<PyAvatar>(m, "Avatar",
                       "An avatar made by create(): betas, rest-pose vertices, input and achieved "
                       "measurements, plausibility. Save it with save().")
      .def_property_readonly(
          "betas", [](const PyAvatar& a) { return vector_copy(a.avatar.betas); },
          "(B,) float64 shape coefficients (zeros beyond the regressor's outputs).")
      .def_property_readonly(
          "covariance",
          [](const PyAvatar& a) -> py::object {
            if (!a.avatar.covariance) return py::none();
            using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
            return matrix_copy(RowMajor(*a.avatar.covariance));
          },
          "(k, k) posterior covariance of the betas (noise-aware regressor), else None.")
      .def_property_readonly(
          "betas_sd",
          [](const PyAvatar& a) -> py::object {
            if (!a.avatar.covariance) return py::none();
            return vector_copy(a.avatar.covariance->diagonal().cwiseSqrt());
          },
          "(k,) posterior SD of the betas (noise-aware regressor), else None.")
      .def_property_readonly(
          "vertices",
          [](const py::object& self) {
            return matrix_view(self.cast<const PyAvatar&>().avatar.vertices, self);
          },
          "(V, 3) float64 rest-pose vertices, metres (read-only view).")
      .def_property_readonly(
          "input", [](const PyAvatar& a) { return to_dict(a.avatar.input); },
          "The inputs as given, SI units.")
      .def_property_readonly(
          "mapped", [](const PyAvatar& a) { return to_dict(a.avatar.mapped); },
          "The inputs after the mapping (equal to input without one).")
      .def_property_readonly(
          "achieved", [](const PyAvatar& a) { return to_dict(a.avatar.achieved); },
          "Measurements of the avatar: the 13, circumferences, volume (m^3), weight (kg).")
      .def_property_readonly(
          "plausibility", [](const PyAvatar& a) { return a.avatar.plausibility; },
          "Plausibility of the regressor's betas.")
      .def_property_readonly(
          "warnings",
          [](const PyAvatar& a) {
            std::vector<std::string> w;
            for (const auto& msg : a.avatar.messages) w.push_back(msg.message);
            return w;
          },
          "Validation messages about the inputs (unusual values; errors when force=True).")
      .def_readonly("regressor", &PyAvatar::regressor, "The regressor used.")
      .def_property_readonly(
          "model", [](const PyAvatar& a) { return a.model; }, "The model it was made from.")
      .def("save", &save_avatar, py::arg("path"), py::arg("extras") = py::none(),
           py::arg("pose_correctives") = false,
           "Writes the avatar by extension, as `caliper create --out`: .glb / .gltf (rigged "
           "and skinned; asset.extras hold generator, regressor, betas, measurements, model, "
           "plus extras), .obj or .ply (rest-pose mesh standing on the floor). Atomic write; "
           "raises ModelError on failure, InvalidInputError for another extension.")
      .def(
          "glb_bytes",
          [](const PyAvatar& a) {
            smpl::GltfOptions o;
            o.extras = default_extras(a);
            std::vector<std::uint8_t> bytes;
            {
              py::gil_scoped_release release;
              bytes = smpl::glb_bytes(*a.model, a.avatar.betas, o);
            }
            return py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
          },
          "The .glb file as bytes (no disk I/O).")
      .def("__repr__", [](const PyAvatar& a) {
        const auto h = a.avatar.achieved.find("height");
        const auto w = a.avatar.achieved.find("weight");
        return "<caliper.Avatar " + a.regressor + " height=" +
               (h == a.avatar.achieved.end() ? std::string("?") : std::to_string(h->second)) +
               " m weight=" +
               (w == a.avatar.achieved.end() ? std::string("?") : std::to_string(w->second)) +
               " kg>";
      });
}

// create: an avatar from measurements.
void bind_create(py::module_& m) {
  m.def(
      "create",
      [](const ModelPtr& model, const RegressorsPtr& regressors, const py::object& measurements,
         const py::object& height, const py::object& weight, const py::object& arm_span,
         const py::object& inseam, const py::object& hip_width, const py::object& arm_length,
         const py::object& regressor, bool exact_inputs, bool force, bool circumferences,
         const py::object& noise, const std::shared_ptr<caliper::MeasurementMapping>& mapping,
         bool shape_curve, const py::object& population) {
        if (!model) invalid("create: model is None; load one with load_model() or open_model()");
        py::dict named;
        named["height"] = height;
        named["weight"] = weight;
        named["arm_span"] = arm_span;
        named["inseam"] = inseam;
        named["hip_width"] = hip_width;
        named["arm_length"] = arm_length;
        CreateRequest r = make_request(measurements, named, regressor, exact_inputs, force,
                                       circumferences, noise, mapping);
        r.shape_curve = shape_curve;
        if (!population.is_none()) {
          // As `caliper create --population`: the population is the noise-aware regressor's
          // prior, so that regressor is taken (another one named is an error).
          const std::string key = population.cast<std::string>();
          if (!regressor.is_none() && r.regressor != "noise-aware")
            invalid(
                "population takes the noise-aware regressor (the population is its prior); "
                "leave out regressor='" +
                r.regressor + "'");
          r.regressor = "noise-aware";
          r.prior = caliper::population_prior(*model, key);
        }
        RegressorsPtr regs = regressors;
        py::gil_scoped_release release;
        if (!regs)
          regs = std::make_shared<caliper::RegressorSet>(caliper::train_regressors(*model));
        return create_avatar(model, *regs, r);
      },
      py::arg("model"), py::arg("regressors") = nullptr, py::arg("measurements") = py::none(),
      py::kw_only(), py::arg("height") = py::none(), py::arg("weight") = py::none(),
      py::arg("arm_span") = py::none(), py::arg("inseam") = py::none(),
      py::arg("hip_width") = py::none(), py::arg("arm_length") = py::none(),
      py::arg("regressor") = py::none(), py::arg("exact_inputs") = false, py::arg("force") = false,
      py::arg("circumferences") = true, py::arg("noise") = py::none(), py::arg("mapping") = nullptr,
      py::arg("shape_curve") = true, py::arg("population") = py::none(),
      "Creates an avatar from measurements, as `caliper create`. Values are numbers in metres "
      "and kilograms or texts with a unit ('168cm', '5ft6in', '62kg', '137lb'), given as "
      "keywords (height, weight, arm_span, inseam, hip_width, arm_length) and/or a dict of "
      "measurement ids. regressors: from train_regressors() or load_regressors() (None trains "
      "them now, about as long as `caliper create` without --regressors). regressor: 'R2', "
      "'R4', 'R5', 'R6' or 'noise-aware' (default: R2/R4/R5 for exactly their inputs, else "
      "noise-aware). exact_inputs: refine R2-R6 betas so every input is reproduced exactly. "
      "shape_curve: R2-R6 start from the general population's body of the height and weight "
      "when the model carries a shape curve (the open models do); False: the paper's. "
      "noise: SD per input for the noise-aware regressor. mapping: a real-to-virtual Mapping. "
      "population: a population the model carries (the open models: 'ansur2', US Army "
      "soldiers; 'nhanes', US adults, their own prior): the noise-aware regressor with its "
      "shapes as the prior (as `caliper create --population`). "
      "force: accept inputs outside the hard limits (else InvalidInputError).");
}

// measure and evaluate.
void bind_measure(py::module_& m) {
  // --- measure ---
  m.def(
      "measure",
      [](const ModelPtr& model, const py::object& vertices, const py::object& betas,
         bool circumferences, bool convex_hull) {
        return to_dict(measure(model, vertices, betas, circumferences, convex_hull));
      },
      py::arg("model"), py::arg("vertices") = py::none(), py::kw_only(),
      py::arg("betas") = py::none(), py::arg("circumferences") = true,
      py::arg("convex_hull") = true,
      "Every measurement `caliper measure` reports for a rest-pose body of model: the paper's "
      "13 (metres), circumferences, volume (m^3) and weight (kg, from volume). Give vertices "
      "((V, 3), metres) or betas.");
  m.def("read_gltf", &read_gltf, py::arg("path"),
        "Reads a .glb / .gltf avatar (as written by Avatar.save): dict with vertices, faces, "
        "joints, joint_names, parents, generator, extras, warnings.");

  // --- evaluate ---
  m.def("evaluate", &evaluate, py::arg("model"), py::arg("betas"), py::arg("poses") = py::none(),
        py::arg("translations") = py::none(), py::kw_only(),
        py::arg("dtype") = py::dtype::of<double>(), py::arg("joints") = false,
        "The SMPL forward pass for one body or a batch. betas: (B',) or (N, B') with B' <= "
        "model.num_betas; poses: None (rest pose) or (N, 3K) / (N, K, 3) axis-angle, radians, "
        "joint 0 = global orientation; translations: None or (N, 3). Inputs of any float dtype. "
        "Returns vertices (N, V, 3) (or (V, 3) for 1-D betas) of dtype float64 or float32, and "
        "with joints=True a tuple (vertices, joints (N, K, 3)). The model's arrays are used in "
        "place (never copied); the GIL is released during the loop.");
}

// The exporters.
void bind_export(py::module_& m) {
  // --- export ---
  m.def(
      "write_gltf",
      [](const std::string& path, const ModelPtr& model, const py::object& betas,
         bool stand_on_floor, bool pose_correctives, const std::string& name,
         const std::optional<std::map<std::string, std::string>>& extras) {
        const Eigen::VectorXd b = to_vector(betas, "betas");
        const smpl::GltfOptions o = gltf_options(stand_on_floor, pose_correctives, name, extras);
        py::gil_scoped_release release;
        smpl::write_gltf(path, *model, b, o);
      },
      py::arg("path"), py::arg("model"), py::arg("betas"), py::kw_only(),
      py::arg("stand_on_floor") = true, py::arg("pose_correctives") = false,
      py::arg("name") = "avatar", py::arg("extras") = py::none(),
      "Writes the rigged, skinned avatar of model with betas as .glb (binary) or .gltf (JSON, "
      "embedded buffer); pose_correctives adds posedirs as morph targets.");
  m.def(
      "glb_bytes",
      [](const ModelPtr& model, const py::object& betas, bool stand_on_floor, bool pose_correctives,
         const std::string& name, const std::optional<std::map<std::string, std::string>>& extras) {
        const Eigen::VectorXd b = to_vector(betas, "betas");
        const smpl::GltfOptions o = gltf_options(stand_on_floor, pose_correctives, name, extras);
        std::vector<std::uint8_t> bytes;
        {
          py::gil_scoped_release release;
          bytes = smpl::glb_bytes(*model, b, o);
        }
        return py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
      },
      py::arg("model"), py::arg("betas"), py::kw_only(), py::arg("stand_on_floor") = true,
      py::arg("pose_correctives") = false, py::arg("name") = "avatar",
      py::arg("extras") = py::none(), "The .glb of write_gltf() as bytes.");
  m.def(
      "write_obj",
      [](const std::string& path, const py::object& vertices, const py::object& faces) {
        const smpl::Vertices v = to_vertices(vertices, "vertices");
        const smpl::Faces f = to_faces(faces, "faces");
        py::gil_scoped_release release;
        smpl::write_obj(path, v, f);
      },
      py::arg("path"), py::arg("vertices"), py::arg("faces"),
      "Writes a Wavefront OBJ of any triangle mesh (vertices (V, 3), faces (F, 3)).");
  m.def(
      "write_ply",
      [](const std::string& path, const py::object& vertices, const py::object& faces) {
        const smpl::Vertices v = to_vertices(vertices, "vertices");
        const smpl::Faces f = to_faces(faces, "faces");
        py::gil_scoped_release release;
        smpl::write_ply(path, v, f);
      },
      py::arg("path"), py::arg("vertices"), py::arg("faces"),
      "Writes a binary little-endian PLY of any triangle mesh.");
}

// Units: parsing and formatting.
void bind_units(py::module_& m) {
  // --- units ---
  m.def(
      "parse_length", [](const std::string& text) { return caliper::parse_length(text, "length"); },
      py::arg("text"), "Metres from a length with its unit: '168cm', '1.68m', '66in', '5ft6in'.");
  m.def(
      "parse_mass", [](const std::string& text) { return caliper::parse_mass(text, "mass"); },
      py::arg("text"), "Kilograms from a mass with its unit: '62kg', '137lb'.");
  m.def(
      "default_regressor",
      [](const py::dict& measurements) {
        return caliper::default_regressor(measurement_map(measurements, "measurements"));
      },
      py::arg("measurements"),
      "The regressor create() picks for these inputs: R2, R4 or R5 for exactly their inputs, "
      "else 'noise-aware'.");
  m.def(
      "normalise_regressor",
      [](const std::string& name) { return caliper::normalise_regressor_name(name, "regressor"); },
      py::arg("name"),
      "'R2', 'R4', 'R5', 'R6' or 'noise-aware' for a regressor name ('r5', 'noise_aware', 'na', "
      "...); raises InvalidInputError.");
  m.def(
      "regressor_inputs",
      [](const std::string& name) {
        const auto k = caliper::parse_regressor_kind(name);
        if (!k) invalid("regressor " + name + ": expected R2, R4, R5 or R6");
        return caliper::regressor_inputs(*k);
      },
      py::arg("name"), "The input ids of R2, R4, R5 or R6.");
  m.def(
      "validate_measurements",
      [](const py::dict& measurements) {
        std::vector<py::dict> out;
        for (const auto& msg :
             caliper::validate_measurements(measurement_map(measurements, "measurements"))) {
          py::dict d;
          d["severity"] = msg.severity == caliper::Severity::Error ? "error" : "warning";
          d["id"] = msg.id;
          d["value"] = msg.value;
          d["min"] = msg.min;
          d["max"] = msg.max;
          d["message"] = msg.message;
          out.push_back(d);
        }
        return out;
      },
      py::arg("measurements"),
      "Range and consistency checks of input measurements: a list of dicts (severity 'error' "
      "or 'warning', id, value, min, max, message); empty when all is well.");
  m.def(
      "plausibility",
      [](const py::object& betas) { return caliper::plausibility(to_vector(betas, "betas")); },
      py::arg("betas"), "Plausibility of a shape vector under betas ~ N(0, I).");
}

// The benchmark baselines.
void bind_benchmarks(py::module_& m) {
  // --- benchmark baselines ---
  m.def("_time_create_cpp", &time_create_cpp, py::arg("model"), py::arg("regressors"),
        py::arg("measurements"), py::arg("regressor") = py::none(), py::arg("repeats") = 100,
        "Benchmark baseline: median thread CPU seconds of the C++ work of create(), timed in C++.");
  m.def("_time_evaluate_cpp", &time_evaluate_cpp, py::arg("model"), py::arg("betas"),
        py::arg("poses") = py::none(), py::arg("float32") = false, py::arg("repeats") = 5,
        "Benchmark baseline: median thread CPU seconds of the C++ loop of evaluate() (float64 or, "
        "with float32=True, float32 output), timed in C++.");
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// 10. Module
// ---------------------------------------------------------------------------------------------

PYBIND11_MODULE(_caliper, m) {
  m.doc() =
      "The Virtual Caliper for Python: SMPL-family body models (load, evaluate, export) and "
      "metrically accurate avatars from body measurements (regressors, create, measure). "
      "Units: metres, kilograms, radians; +Y up, the body faces +Z. See docs/library.md.";
  m.attr("__version__") = CALIPER_VERSION;
  register_errors(m);

  bind_model(m);
  bind_regressors(m);
  bind_mapping(m);
  bind_avatar(m);
  bind_create(m);
  bind_measure(m);
  bind_export(m);
  bind_units(m);
  bind_benchmarks(m);
}
