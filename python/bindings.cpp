// SPDX-License-Identifier: BSD-3-Clause
// Python bindings (issue #18): the per-cloud model, the query and its batch, with the C++ structs'
// own defaults. numpy points become a pcl::PointCloud<pcl::PointXYZ> once and go through
// buildCloudModel<pcl::PointXYZ>, so a Python model is exactly the C++ model of the same floats.
#include "cli_options.h"
#include "cloud_input.h"
#include "input_warnings.h"
#include "quiet_pcl_console.h"
#include "result_json.h"
#include "mesh_input.h"
#include "mesh_sampling.h"

#include <pcl_probcollision/cloud_model.h>
#include <pcl_probcollision/cloud_model_params.h>
#include <pcl_probcollision/collision.h>
#include <pcl_probcollision/collision_request.h>
#include <pcl_probcollision/collision_result.h>
#include <pcl_probcollision/error_message.h>
#include <pcl_probcollision/organized_sensor_pose.h>
#include <pcl_probcollision/sensor_noise.h>
#include <pcl_probcollision/version.h>
#include <pcl_probcollision/detail/input_checks.h>
#include <pcl_probcollision/detail/parallel.h>

#include <pcl/common/io.h>
#include <pcl/exceptions.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <fstream>
#include <future>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace py = pybind11;
using namespace pcl_probcollision;

namespace
{
/** \brief A `threads` argument: any Python integer (operator.index), kept whole so that
  * checkThreads refuses a huge one with its ValueError; pybind11's int caster refuses an int
  * beyond C int with the TypeError of a wrong type (threads=10**12). */
struct ThreadsArg
{
  long long value = 0;  // saturated at long long's range, which text then says exactly
  std::string text;     // str() of the Python int
};
} // namespace

namespace pybind11::detail
{
template <>
struct type_caster<ThreadsArg>
{
  PYBIND11_TYPE_CASTER (ThreadsArg, const_name ("int"));

  bool
  load (handle src, bool)
  {
    // As pybind11's int caster: a float (and a str) is no count, a TypeError.
    if (PyFloat_Check (src.ptr ()) || !PyIndex_Check (src.ptr ()))
      return false;
    const object index = reinterpret_steal<object> (PyNumber_Index (src.ptr ()));
    if (!index)
    {
      PyErr_Clear ();
      return false;
    }
    int overflow = 0;
    const long long v = PyLong_AsLongLongAndOverflow (index.ptr (), &overflow);
    if (v == -1 && PyErr_Occurred ())
    {
      PyErr_Clear ();
      return false;
    }
    value.value = overflow > 0 ? std::numeric_limits<long long>::max ()
                               : overflow < 0 ? std::numeric_limits<long long>::min () : v;
    value.text = str (index);
    return true;
  }

  static handle
  cast (const ThreadsArg& t, return_value_policy, handle)
  {
    return PyLong_FromLongLong (t.value);
  }
};
} // namespace pybind11::detail

namespace
{
using ModelPtr = std::shared_ptr<CloudModel>;

/** \brief s as Python text: bytes that are not UTF-8 (a path's, os.fsencode of a name that is
  * not) as \xNN escapes, Python's backslashreplace. PyErr_SetString and pybind11 read C++
  * strings as UTF-8: a message naming such a path was an empty ValueError. */
std::string
utf8Text (const std::string& s)
{
  const py::object text = py::reinterpret_steal<py::object> (
      PyUnicode_DecodeUTF8 (s.data (), static_cast<py::ssize_t> (s.size ()), "backslashreplace"));
  if (!text)
    throw py::error_already_set ();
  return text.cast<std::string> ();
}

/** \brief ValueError naming `name` when it holds a NUL: the messages naming the cloud (PCL's
  * exceptions, PyErr_SetString, warnings) are C strings, which a NUL would cut. */
void
checkName (const std::string& name)
{
  if (const auto nul = name.find ('\0'); nul != std::string::npos)
    throw py::value_error ("name: contains a NUL character (at index " + std::to_string (nul) +
                           "), which would cut the messages naming the cloud, got " +
                           std::string (py::repr (py::str (name))));
}

std::string
shapeOf (const py::array& a)
{
  std::ostringstream s;
  s << '(';
  for (py::ssize_t i = 0; i < a.ndim (); ++i)
    s << (i ? ", " : "") << a.shape (i);
  s << (a.ndim () == 1 ? ",)" : ")");
  return s.str ();
}

std::string
typeName (const py::handle& h)
{
  return py::str (py::type::handle_of (h).attr ("__name__"));
}

/** obj as T, or TypeError naming the argument (pybind11's own cast error is a RuntimeError). */
template <typename T>
T
castArgument (const py::object& obj, const char* name, const char* type)
{
  try
  {
    return obj.cast<T> ();
  }
  catch (const py::cast_error&)
  {
    throw py::type_error (std::string (name) + ": expected " + type + " or None, got " + typeName (obj));
  }
}

/** The array behind a float32 / float64 argument of the given rank, its dims from free_dims on
  * each 3, or TypeError / ValueError naming the argument. */
py::array
floatArray (const py::object& obj, const char* arg, int ndim, const char* expected, int free_dims = 1)
{
  if (!py::isinstance<py::array> (obj))
    throw py::type_error (std::string (arg) + ": expected a numpy array of shape " + expected +
                          ", float32 or float64, got " + typeName (obj));
  py::array a = py::reinterpret_borrow<py::array> (obj);
  if (!py::isinstance<py::array_t<float>> (a) && !py::isinstance<py::array_t<double>> (a))
    throw py::type_error (std::string (arg) + ": expected dtype float32 or float64 (native byte order), got " +
                          std::string (py::str (a.dtype ())));
  bool ok = a.ndim () == ndim;
  for (int d = free_dims; ok && d < ndim; ++d)
    ok = a.shape (d) == 3;
  if (!ok)
    throw py::value_error (std::string (arg) + ": expected shape " + expected + ", got " + shapeOf (a));
  return a;
}

template <typename T>
void
fillPoints (const py::array& arr, pcl::PointCloud<pcl::PointXYZ>& cloud, const Eigen::Vector3d& offset = Eigen::Vector3d::Zero ())
{
  const auto a = arr.unchecked<T, 2> ();
  cloud.resize (static_cast<std::size_t> (a.shape (0)));
  cloud.width = static_cast<std::uint32_t> (a.shape (0));
  cloud.height = 1;
  cloud.is_dense = false;
  for (py::ssize_t i = 0; i < a.shape (0); ++i)
  {
    pcl::PointXYZ& p = cloud[static_cast<std::size_t> (i)];
    p.x = static_cast<float> (static_cast<double> (a (i, 0)) - offset.x ());
    p.y = static_cast<float> (static_cast<double> (a (i, 1)) - offset.y ());
    p.z = static_cast<float> (static_cast<double> (a (i, 2)) - offset.z ());
    // float64 finite in double but beyond float: it would silently become Inf and be skipped.
    if (!std::is_same<T, float>::value)
      for (int d = 0; d < 3; ++d)
        if (std::isfinite (static_cast<double> (a (i, d))) && !std::isfinite (p.data[d]))
          throw py::value_error ("points: row " + std::to_string (i) +
                                 " has a coordinate beyond the float range (points are stored as float32)");
  }
}

template <typename T>
void
fillCovariances (const py::array& arr, pcl::PointCloud<Covariance>& covs)
{
  const auto a = arr.unchecked<T, 3> ();
  covs.resize (static_cast<std::size_t> (a.shape (0)));
  covs.width = static_cast<std::uint32_t> (a.shape (0));
  covs.height = 1;
  for (py::ssize_t i = 0; i < a.shape (0); ++i)
  {
    Eigen::Matrix3d m;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        m (r, c) = static_cast<double> (a (i, r, c));
    if (m.allFinite ())
      for (int r = 0; r < 3; ++r)
        for (int c = r + 1; c < 3; ++c)
          if (std::abs (m (r, c) - m (c, r)) > 1e-6 * (std::abs (m (r, c)) + std::abs (m (c, r))) + 1e-30)
            throw py::value_error ("covariances: matrix " + std::to_string (i) + " is not symmetric");
    // float64 finite in double but beyond float: it would silently become Inf and its point be
    // skipped, as a point's coordinate would (fillPoints).
    if (m.allFinite () && !(m.cwiseAbs ().maxCoeff () <= static_cast<double> (std::numeric_limits<float>::max ())))
      throw py::value_error ("covariances: matrix " + std::to_string (i) +
                             " has an entry beyond the float range (covariances are stored as float32)");
    covs[static_cast<std::size_t> (i)] = m.allFinite () ? Covariance (m) : Covariance::nan ();
  }
}

/** Outward unit normals (N, 3) index-aligned with the points, as pcl::PointNormal's normal_x/y/z:
  * a row with a NaN or a zero normal has none (the surface model orients it from its neighbours). */
template <typename T>
void
fillNormals (const py::array& arr, pcl::PointCloud<pcl::PointNormal>& cloud, bool any_length)
{
  const auto a = arr.unchecked<T, 2> ();
  for (py::ssize_t i = 0; i < a.shape (0); ++i)
  {
    pcl::PointNormal& p = cloud[static_cast<std::size_t> (i)];
    p.normal_x = static_cast<float> (a (i, 0));
    p.normal_y = static_cast<float> (a (i, 1));
    p.normal_z = static_cast<float> (a (i, 2));
    const Eigen::Vector3f n (p.normal_x, p.normal_y, p.normal_z);
    if (!any_length && n.allFinite () && n.squaredNorm () > 0.0f && std::abs (n.norm () - 1.0f) > 1e-3f)
      throw py::value_error ("normals: row " + std::to_string (i) + " is not of unit length (norm " +
                             std::to_string (n.norm ()) + "); give unit normals, or NaN / 0 for none");
  }
}

/** Where float64 points lie so far from the origin, against their own extent, that float32 would
  * round them (beyond 16 extents, float's step there exceeds 1e-6 of the extent): the centre of
  * their box, which build_model subtracts in double before the points become float32
  * (offsetModel); zero otherwise, so that a cloud near the origin gives the bits it always gave. */
Eigen::Vector3d
farOffset (const py::array& arr)
{
  const auto a = arr.unchecked<double, 2> ();
  Eigen::Vector3d low = Eigen::Vector3d::Constant (std::numeric_limits<double>::infinity ()), high = -low;
  for (py::ssize_t i = 0; i < a.shape (0); ++i)
  {
    const Eigen::Vector3d p (a (i, 0), a (i, 1), a (i, 2));
    if (!p.allFinite ())
      continue;
    low = low.cwiseMin (p);
    high = high.cwiseMax (p);
  }
  if (!(low.array () <= high.array ()).all ())
    return Eigen::Vector3d::Zero ();  // no finite point
  const double extent = (high - low).maxCoeff ();
  const double far = std::max (low.cwiseAbs ().maxCoeff (), high.cwiseAbs ().maxCoeff ());
  return far > 16.0 * extent && far > 1.0 ? Eigen::Vector3d (0.5 * (low + high)) : Eigen::Vector3d::Zero ();
}

/** An (N, 3) float32 / float64 array as pcl::PointXYZ (fillPoints), arg naming it in errors; with
  * image, an (H, W, 3) image of points as an organized cloud, W x H (its rows in order). With
  * offset, float64 points far from the origin are given about farOffset() (else offset is zero). */
pcl::PointCloud<pcl::PointXYZ>
cloudOf (const py::object& points, const char* arg, bool image = false, Eigen::Vector3d* offset = nullptr)
{
  const py::array given = image ? floatArray (points, arg, 3, "(H, W, 3)", 2) : floatArray (points, arg, 2, "(N, 3)");
  const py::array pts = image ? py::array (given.attr ("reshape") (py::make_tuple (-1, 3))) : given;
  pcl::PointCloud<pcl::PointXYZ> cloud;
  if (offset)
    offset->setZero ();
  if (py::isinstance<py::array_t<float>> (pts))
    fillPoints<float> (pts, cloud);
  else
  {
    if (offset)
      *offset = farOffset (pts);
    fillPoints<double> (pts, cloud, offset ? *offset : Eigen::Vector3d::Zero ());
  }
  if (image)
  {
    cloud.width = static_cast<std::uint32_t> (given.shape (1));
    cloud.height = static_cast<std::uint32_t> (given.shape (0));
  }
  return cloud;
}

/** model, just built from points given about offset, with its origin moved there (offsetModel). */
std::shared_ptr<const CloudModel>
offsetBuilt (std::shared_ptr<const CloudModel> model, const Eigen::Vector3d& offset)
{
  if (!offset.isZero ())
    offsetModel (const_cast<CloudModel&> (*model), offset);
  return model;
}

std::shared_ptr<const CloudModel>
buildModel (const py::object& points, const py::object& covariances, const py::object& params_obj,
            const std::string& name, const py::object& viewpoint = py::none (),
            const py::object& normals = py::none (), bool any_length_normals = false)
{
  checkName (name);
  // An (H, W, 3) image of points is an organized cloud, W x H: its rows and columns say where its
  // sensor was (organizedSensorPose), as a file's WIDTH and HEIGHT do for load_model. Its
  // covariances and normals come per pixel, (H, W, 3, 3) and (H, W, 3), or flattened.
  const bool image = py::isinstance<py::array> (points) && py::reinterpret_borrow<py::array> (points).ndim () == 3;
  // float64 points far from the origin are taken about an offset, in double (offsetModel): as
  // float32 they lost what the model keeps (a cube 1 cm into a table in a UTM frame read free).
  Eigen::Vector3d offset;
  pcl::PointCloud<pcl::PointXYZ> cloud = cloudOf (points, "points", image, &offset);
  const auto flattened = [&] (const py::object& obj, int image_ndim) {
    if (!image || !py::isinstance<py::array> (obj) || py::reinterpret_borrow<py::array> (obj).ndim () != image_ndim)
      return obj;
    const py::array a = py::reinterpret_borrow<py::array> (obj);
    if (a.shape (0) != py::ssize_t (cloud.height) || a.shape (1) != py::ssize_t (cloud.width))
      return obj;  // refused below by its shape
    py::list shape;
    shape.append (-1);
    for (int d = 2; d < image_ndim; ++d)
      shape.append (a.shape (d));
    return py::object (a.attr ("reshape") (py::tuple (shape)));
  };
  const std::string points_count = std::to_string (cloud.size ());

  pcl::PointCloud<Covariance> covs;
  const bool have_covs = !covariances.is_none ();
  if (have_covs)
  {
    const py::array c = floatArray (flattened (covariances, 4), "covariances", 3, "(N, 3, 3) or (H, W, 3, 3)");
    if (std::size_t (c.shape (0)) != cloud.size ())
      throw py::value_error ("covariances: " + std::to_string (c.shape (0)) + " matrices for " + points_count + " points");
    if (py::isinstance<py::array_t<float>> (c))
      fillCovariances<float> (c, covs);
    else
      fillCovariances<double> (c, covs);
  }
  const CloudModelParams params = params_obj.is_none () ? CloudModelParams () : castArgument<CloudModelParams> (params_obj, "params", "CloudModelParams");
  if (!viewpoint.is_none ())
  {
    // PCD's VIEWPOINT: tx ty tz qw qx qy qz, the sensor pose the depth noise models use.
    auto v = py::array_t<double, py::array::forcecast>::ensure (viewpoint);
    if (!v || v.size () != 7)
    {
      PyErr_Clear ();
      throw py::value_error ("viewpoint: expected 7 numbers tx ty tz qw qx qy qz (a PCD's VIEWPOINT)");
    }
    const double* d = v.data ();
    for (int i = 0; i < 7; ++i)
      if (!std::isfinite (d[i]))
        throw py::value_error ("viewpoint: value " + std::to_string (i + 1) + " is not finite (tx ty tz qw qx qy qz)");
    cloud.sensor_origin_ = Eigen::Vector4f (static_cast<float> (d[0] - offset.x ()), static_cast<float> (d[1] - offset.y ()),
                                            static_cast<float> (d[2] - offset.z ()), 0.f);
    cloud.sensor_orientation_ = Eigen::Quaternionf (static_cast<float> (d[3]), static_cast<float> (d[4]),
                                                    static_cast<float> (d[5]), static_cast<float> (d[6]));
  }
  else if (!offset.isZero ())  // PCL's default viewpoint stays where it was: the frame's origin
    cloud.sensor_origin_ = Eigen::Vector4f (static_cast<float> (-offset.x ()), static_cast<float> (-offset.y ()),
                                            static_cast<float> (-offset.z ()), 0.f);

  if (!normals.is_none ())
  {
    // pcl::PointNormal: the same x y z (the same model) plus the normals the surface layer's Auto
    // and PointNormals orientations take, as pcd_collision builds a mesh's model.
    const py::array nrm = floatArray (flattened (normals, 3), "normals", 2, "(N, 3) or (H, W, 3)");
    if (std::size_t (nrm.shape (0)) != cloud.size ())
      throw py::value_error ("normals: " + std::to_string (nrm.shape (0)) + " normals for " + points_count + " points");
    pcl::PointCloud<pcl::PointNormal> oriented;
    oriented.resize (cloud.size ());
    oriented.width = cloud.width;
    oriented.height = cloud.height;
    oriented.is_dense = cloud.is_dense;
    oriented.sensor_origin_ = cloud.sensor_origin_;
    oriented.sensor_orientation_ = cloud.sensor_orientation_;
    for (std::size_t i = 0; i < cloud.size (); ++i)
      oriented[i].getVector3fMap () = cloud[i].getVector3fMap ();
    if (py::isinstance<py::array_t<float>> (nrm))
      fillNormals<float> (nrm, oriented, any_length_normals);
    else
      fillNormals<double> (nrm, oriented, any_length_normals);
    // Only the surface model reads them: without it they changed nothing, without a word (a probe,
    // 2026-12-06).
    if (!params.surface &&
        PyErr_WarnEx (PyExc_RuntimeWarning,
                      (name + ": normals given without params.surface: only the surface model reads them, so they are "
                              "not used (CloudModelParams(surface=True) builds it)")
                          .c_str (),
                      1) < 0)
      throw py::error_already_set ();
    py::gil_scoped_release release;
    return offsetBuilt (buildCloudModel<pcl::PointNormal> (oriented, params, nullptr, have_covs ? &covs : nullptr, name),
                        offset);
  }
  py::gil_scoped_release release;
  return offsetBuilt (buildCloudModel<pcl::PointXYZ> (cloud, params, nullptr, have_covs ? &covs : nullptr, name), offset);
}

/** FileNotFoundError for a missing path, IsADirectoryError for a directory, ValueError for
  * another kind of file: what Python's open() raises, before any reader sees the path. */
void
requireRegularFile (const std::filesystem::path& path)
{
  std::error_code ec;
  const auto status = std::filesystem::status (path, ec);
  if (std::filesystem::is_regular_file (status))
    return;
  const bool directory = std::filesystem::is_directory (status);
  if (!directory && std::filesystem::exists (status))
    throw py::value_error ("path: '" + path.string () + "' is not a regular file");
  PyObject* type = directory ? PyExc_IsADirectoryError : PyExc_FileNotFoundError;
  // The file name as os.fsdecode gives it (what open() puts in filename): a name that is not
  // UTF-8 keeps its bytes as surrogates, where a UTF-8 cast raised UnicodeDecodeError.
  const py::object filename = py::reinterpret_steal<py::object> (
      PyUnicode_DecodeFSDefaultAndSize (path.native ().data (), static_cast<py::ssize_t> (path.native ().size ())));
  if (!filename)
    throw py::error_already_set ();
  py::object err = py::reinterpret_borrow<py::object> (type) (directory ? 21 : 2,
                                                                std::string (directory ? "Is a directory" : "No such file"),
                                                                filename);
  PyErr_SetObject (type, err.ptr ());
  throw py::error_already_set ();
}

std::shared_ptr<const CloudModel>
loadModel (const std::filesystem::path& path, const py::object& params_obj, const py::object& name_obj,
           std::string& file_warning)
{
  requireRegularFile (path);
  std::string ext = path.extension ().string ();
  for (char& ch : ext)
    ch = static_cast<char> (std::tolower (static_cast<unsigned char> (ch)));
  // What pcd_collision reads as a cloud: a .pcd, or a .ply declaring no face (one with faces is
  // a mesh, whose samples read_mesh and sample_mesh give).
  if (ext == ".ply" && !pcl_probcollision::io::isFacelessPly (path.string ()))
    throw py::value_error ("path: '" + path.string () + "' is a mesh (its header declares faces) or not a readable "
                           ".ply; read_mesh and sample_mesh (or sample_mesh_with_normals) give a mesh's samples");
  if (ext != ".pcd" && ext != ".ply")
    throw py::value_error ("path: only .pcd and face-less .ply files are read, got '" + path.string () + "'");
  const CloudModelParams params = params_obj.is_none () ? CloudModelParams () : castArgument<CloudModelParams> (params_obj, "params", "CloudModelParams");
  const std::string name = name_obj.is_none () ? utf8Text (path.filename ().string ()) : castArgument<std::string> (name_obj, "name", "str");
  checkName (name);

  // io::loadCloud is pcd_collision's reader: every check a file of unknown origin needs (PCL
  // 1.13's PCDReader crashes on a header without FIELDS), messages naming the file. With a
  // surface, the file's normals too (loadCloudWithNormals), as pcd_collision -surface reads them:
  // when the file has normal_x normal_y normal_z, the model is built from pcl::PointNormal, as
  // build_model(normals=) builds it.
  pcl::PointCloud<pcl::PointXYZ> cloud;
  pcl::PointCloud<pcl::PointNormal> oriented;
  bool has_normals = false;
  pcl_probcollision::io::XyzRounding rounding;
  std::string error;
  bool loaded = false;
  {
    py::gil_scoped_release release;
    loaded = params.surface ? pcl_probcollision::io::loadCloudWithNormals (path.string (), oriented, has_normals, error, &rounding)
                            : pcl_probcollision::io::loadCloud (path.string (), cloud, error, &rounding);
  }
  if (!loaded)
    throw py::value_error ("path: " + error);
  py::gil_scoped_release release;
  namespace io = pcl_probcollision::io;
  if (has_normals)
  {
    file_warning = io::roundingWarning (io::cloudFacts (path.string (), oriented, rounding, params.noise));
    return buildCloudModel<pcl::PointNormal> (oriented, params, nullptr, nullptr, name);
  }
  if (params.surface)
    pcl::copyPointCloud (oriented, cloud);
  file_warning = io::roundingWarning (io::cloudFacts (path.string (), cloud, rounding, params.noise));
  return buildCloudModel<pcl::PointXYZ> (cloud, params, nullptr, nullptr, name);
}

/** The built model, after a RuntimeWarning with its precision warning (CloudModel::warning), if
  * it has one: the library prints it through PCL's console, which a Python user does not watch.
  * Under warnings.simplefilter("error") the warning is raised instead. Holds the GIL. */
std::shared_ptr<CloudModel>
warnedModel (const CloudModel::ConstPtr& model)
{
  if (!model->warning ().empty () && PyErr_WarnEx (PyExc_RuntimeWarning, model->warning ().c_str (), 1) < 0)
    throw py::error_already_set ();
  return std::const_pointer_cast<CloudModel> (model);
}

/** obj as a float64 array (a nested list too), or TypeError naming `what` for anything that is no
  * array of real numbers: numpy's own cast would keep a complex number's real part (5j read as 0)
  * and parse a string in an object array. `expected` says what was expected. */
py::array_t<double, py::array::forcecast>
realArray (const py::object& obj, const std::string& what, const std::string& expected)
{
  const py::array raw = py::array::ensure (obj);
  if (!raw)
  {
    PyErr_Clear ();
    throw py::type_error (what + ": expected " + expected + ", got " + typeName (obj));
  }
  const char kind = raw.dtype ().kind ();
  if (raw.size () > 0 && kind != 'f' && kind != 'i' && kind != 'u')
    throw py::type_error (what + ": expected " + expected + " of real numbers, got dtype " +
                          py::str (raw.dtype ()).cast<std::string> ());
  auto a = py::array_t<double, py::array::forcecast>::ensure (raw);
  if (!a)
  {
    PyErr_Clear ();
    throw py::type_error (what + ": expected " + expected + ", got " + typeName (obj));
  }
  return a;
}

/** A 4x4 rigid transform from a 4x4 array (or nested list) or a pair (R, t). */
Eigen::Isometry3d
toPose (const py::object& obj, const char* arg)
{
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity ();
  const std::string expected = std::string (arg) + ": expected a 4x4 matrix or a pair (R, t), R 3x3 and t of 3";
  // A pair is (R, t); any other sequence (a nested 4x4 list) is read as the matrix.
  if ((py::isinstance<py::tuple> (obj) || py::isinstance<py::list> (obj)) && py::len (obj) == 2)
  {
    py::sequence seq = py::reinterpret_borrow<py::sequence> (obj);
    const auto R = realArray (seq[0], arg, "R of a pair (R, t)");
    // C order: t may be a (3,), (3, 1) or (1, 3) view of a larger array (a column of a 4x4).
    const auto t = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure (realArray (seq[1], arg, "t of a pair (R, t)"));
    if (!t)
    {
      PyErr_Clear ();
      throw py::type_error (expected + ", got non-numeric entries");
    }
    if (R.ndim () != 2 || R.shape (0) != 3 || R.shape (1) != 3 || t.size () != 3)
      throw py::value_error (expected + ", got R " + shapeOf (R) + " and t " + shapeOf (t));
    const auto r = R.unchecked<2> ();
    for (int i = 0; i < 3; ++i)
    {
      for (int j = 0; j < 3; ++j)
        m (i, j) = r (i, j);
      m (i, 3) = t.data ()[i];
    }
  }
  else
  {
    const auto a = realArray (obj, arg, "a 4x4 matrix or a pair (R, t)");
    if (a.ndim () != 2 || a.shape (0) != 4 || a.shape (1) != 4)
      throw py::value_error (expected + ", got shape " + shapeOf (a));
    const auto r = a.unchecked<2> ();
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        m (i, j) = r (i, j);
    // A NaN anywhere is said as such, before the last row's test that it would fail too.
    if (!m.allFinite ())
      throw py::value_error (std::string (arg) + ": the pose is not finite (NaN or infinite entries)");
    if (const std::string row = pcl_probcollision::detail::lastRowError (m); !row.empty ())
      throw py::value_error (std::string (arg) + ": " + row);
  }
  Eigen::Isometry3d T;
  T.matrix () = m;
  return T;
}

CollisionRequest
requestOf (const py::object& obj)
{
  CollisionRequest request = obj.is_none () ? CollisionRequest () : castArgument<CollisionRequest> (obj, "request", "CollisionRequest");
  request.validate ();
  return request;
}

/** \brief pcd_collision's units warning (io::scaleWarning) for two models, as a RuntimeWarning:
  * a model built from millimetres queried against one in metres answers for the numbers given (a
  * plate stuck through a table read free). Python shows it once a calling line by default. */
void
warnUnits (const CloudModel& a, const CloudModel& b)
{
  const auto facts = [] (const char* name, const CloudModel& m) {
    io::InputFacts in;
    in.path = name;
    in.finite = m.size ();
    in.diagonal = m.diagonal ();
    return in;
  };
  const std::string warning = io::scaleWarning (facts ("a", a), facts ("b", b));
  if (!warning.empty () && PyErr_WarnEx (PyExc_RuntimeWarning, warning.c_str (), 1) < 0)
    throw py::error_already_set ();
}

CollisionResult
collideOne (const ModelPtr& a, const ModelPtr& b, const py::object& pose, const py::object& request_obj, bool check_units)
{
  if (check_units)
    warnUnits (*a, *b);
  const Eigen::Isometry3d T = toPose (pose, "pose");
  const CollisionRequest request = requestOf (request_obj);
  CollisionResult result;
  {
    py::gil_scoped_release release;
    collide (*a, *b, T, request, result);
  }
  if (result.status == CollisionResult::Status::InvalidInput)
    throw py::value_error (result.message);
  return result;
}

/** \brief The count, or ValueError naming `threads` for one pcd_collision's -threads refuses
  * (above the library's kMaxThreads, or negative, however large): one rule, detail::threadsRangeError. */
int
checkThreads (const ThreadsArg& threads)
{
  const bool in_int = threads.value >= std::numeric_limits<int>::min () && threads.value <= std::numeric_limits<int>::max ();
  const int count = in_int ? static_cast<int> (threads.value) : (threads.value < 0 ? -1 : detail::kMaxThreads + 1);
  if (const std::string why = detail::threadsRangeError (count); !why.empty ())
    throw py::value_error ("threads: " + why + ", got " + threads.text);
  return count;
}

/** CloudModelParams.noise_resolution_gate by name (the constructor and the attribute). */
void
setResolutionGate (CloudModelParams& p, const std::string& v)
{
  if (!CloudModelParams::resolutionGateFromName (v, p.noise_resolution_gate))
    throw py::value_error ("noise_resolution_gate: expected one of everywhere, spacing, cloud, got '" + v + "'");
}

/** CloudModelParams.split: the hierarchy's split style by name, 'pca' or 'octree'. */
std::string
splitName (const CloudModelParams& p)
{
  return p.hierarchy.split_style == BVHParams::SplitStyle::Octree ? "octree" : "pca";
}

void
setSplit (CloudModelParams& p, const std::string& v)
{
  if (v != "pca" && v != "octree")
    throw py::value_error ("split: expected 'pca' or 'octree', got '" + v + "'");
  p.hierarchy.split_style = v == "octree" ? BVHParams::SplitStyle::Octree : BVHParams::SplitStyle::Pca;
}

/** CloudModelParams.leakage_bound: how the hierarchy combines a box's slab probabilities
  * (BVHParams::leakage_bound), 'min_slab' or 'union_bound'. */
std::string
leakageName (const CloudModelParams& p)
{
  return p.hierarchy.leakage_bound == BVHParams::LeakageBound::UnionBound ? "union_bound" : "min_slab";
}

void
setLeakage (CloudModelParams& p, const std::string& v)
{
  if (v != "min_slab" && v != "union_bound")
    throw py::value_error ("leakage_bound: expected 'min_slab' or 'union_bound', got '" + v + "'");
  p.hierarchy.leakage_bound = v == "union_bound" ? BVHParams::LeakageBound::UnionBound : BVHParams::LeakageBound::MinSlab;
}

/** The k-th pose of an (M, 4, 4) array: ValueError naming it when it is not finite or its last row
  * is not 0 0 0 1, and with `rigid` when collide()'s rigid check (detail::poseError) fails; with
  * `rigid`, the pose collide() uses (detail::rigidPose: a rounded rotation's nearest). */
Eigen::Isometry3d
poseAt (const py::detail::unchecked_reference<double, 3>& p, py::ssize_t k, bool rigid)
{
  const std::string name = "poses[" + std::to_string (k) + "]";
  Eigen::Matrix4d m;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      m (i, j) = p (k, i, j);
  if (!m.allFinite ())
    throw py::value_error (name + ": the pose is not finite (NaN or infinite entries)");
  if (const std::string row = pcl_probcollision::detail::lastRowError (m); !row.empty ())
    throw py::value_error (name + ": " + row);
  Eigen::Isometry3d T;
  T.matrix () = m;
  if (rigid)
  {
    const std::string error = pcl_probcollision::detail::poseError (T, name);
    if (!error.empty ())
      throw py::value_error (error);
    return pcl_probcollision::detail::rigidPose (T);  // what collide() uses for it
  }
  return T;
}

/** An (M, 4, 4) array of poses: TypeError for what is no numeric array, ValueError naming the shape
  * of one that is not (M, 4, 4). */
py::array_t<double, py::array::forcecast>
poseArray (const py::object& obj)
{
  const auto a = realArray (obj, "poses", "a numeric array of shape (M, 4, 4)");
  if (a.ndim () != 3 || a.shape (1) != 4 || a.shape (2) != 4)
    throw py::value_error ("poses: expected shape (M, 4, 4), got " + shapeOf (a));
  return a;
}

/** Runs work (a batch given the `ready` callback collideBatch calls after each pose) on a thread of
  * its own, while the calling thread waits without the GIL and checks for signals every 50 ms:
  * Ctrl-C stops the batch at its next pose (ready throws) and raises KeyboardInterrupt here, where
  * a call of 60,000 poses went on for half a minute before. Signals reach the main thread only, so
  * a call from another Python thread runs to its end, as before. A batch of at most
  * kInlineBatch poses runs on the calling thread (without the GIL), as collide() does: a thread
  * of its own costs a call about 70 us (free poses: 5.8 us a pose in batches of 17, 1.2 in
  * batches of 16), and its per-thread scratch starts empty (a probe, 2026-12-06). */
template <typename Work>
void
runInterruptibly (std::size_t count, Work&& work)
{
  struct Interrupted
  {
  };
  std::atomic<bool> stop{false};
  const std::function<void (std::size_t)> ready = [&stop] (std::size_t) {
    if (stop.load (std::memory_order_relaxed))
      throw Interrupted{};
  };
  constexpr std::size_t kInlineBatch = 16;
  if (count <= kInlineBatch)
  {
    py::gil_scoped_release release;
    work (ready);
    return;
  }
  std::future<void> done;
  try
  {
    done = std::async (std::launch::async, [&] { work (ready); });
  }
  catch (const std::system_error&)  // no thread to be had: the batch on this one, as before
  {
    py::gil_scoped_release release;
    work (ready);
    return;
  }
  for (;;)
  {
    bool finished = false;
    {
      py::gil_scoped_release release;
      finished = done.wait_for (std::chrono::milliseconds (50)) == std::future_status::ready;
    }
    if (finished)
      break;
    if (PyErr_CheckSignals () != 0)  // a handler raised (KeyboardInterrupt): stop, then raise it
    {
      stop = true;
      {
        py::gil_scoped_release release;
        done.wait ();
      }
      try
      {
        done.get ();
      }
      catch (...)  // Interrupted, or whatever else ended the batch: the signal's exception is raised
      {
      }
      throw py::error_already_set ();
    }
  }
  done.get ();
}

std::vector<CollisionResult>
collideMany (const ModelPtr& a, const ModelPtr& b, const py::object& poses_obj, const py::object& request_obj,
             const ThreadsArg& threads_arg, bool check_units)
{
  const auto poses = poseArray (poses_obj);
  const int threads = checkThreads (threads_arg);
  if (check_units)
    warnUnits (*a, *b);
  const CollisionRequest request = requestOf (request_obj);
  const auto p = poses.unchecked<3> ();
  std::vector<Eigen::Isometry3d> T (static_cast<std::size_t> (p.shape (0)));
  for (py::ssize_t k = 0; k < p.shape (0); ++k)
    T[static_cast<std::size_t> (k)] = poseAt (p, k, false);
  std::vector<CollisionResult> results;
  runInterruptibly (T.size (), [&] (const std::function<void (std::size_t)>& ready) {
    collideBatch (*a, *b, T, request, results, threads, nullptr, ready);
  });
  for (std::size_t k = 0; k < results.size (); ++k)
    if (results[k].status == CollisionResult::Status::InvalidInput)
      throw py::value_error ("poses[" + std::to_string (k) + "]: " + results[k].message);
  return results;
}

py::array_t<double>
vec3 (const Eigen::Vector3d& v)
{
  py::array_t<double> out (3);
  for (int i = 0; i < 3; ++i)
    out.mutable_at (i) = v[i];
  return out;
}

py::array_t<float>
floats (const std::vector<float>& v)
{
  py::array_t<float> out (static_cast<py::ssize_t> (v.size ()));
  std::copy (v.begin (), v.end (), out.mutable_data ());
  return out;
}

std::string
num (double v)
{
  return py::repr (py::float_ (v));  // Python's shortest round-trip form
}

/** \brief A bound enum value's Python name ("Free", "SurfaceLayer"): the py::enum_ registrations
  * below own those names, the reprs read them from there. */
template <typename E>
std::string
enumName (E value)
{
  return py::cast (value).attr ("name").template cast<std::string> ();
}

/** ClassifierParams(...) with every member, for its repr and CollisionRequest's. */
std::string
classifierRepr (const ClassifierParams& c)
{
  const auto flag = [] (bool b) { return std::string (b ? "True" : "False"); };
  return "ClassifierParams(kernel=KernelMode." + enumName (c.kernel) + ", training=TrainingMode." +
         enumName (c.training) + ", confidence=" + num (c.confidence) + ", gamma_cap=" + num (c.gamma_cap) +
         ", C=" + num (c.C) + ", rbf_gamma=" + num (c.rbf_gamma) + ", rff_features=" + std::to_string (c.rff_features) +
         ", rff_features_large=" + std::to_string (c.rff_features_large) + ", rff_seed=" + std::to_string (c.rff_seed) +
         ", ladder_depth_sigmas=" + num (c.ladder_depth_sigmas) + ", ladder_fraction=" + num (c.ladder_fraction) +
         ", exact_points_in_maximum=" + flag (c.exact_points_in_maximum) +
         ", max_iterations=" + std::to_string (c.max_iterations) + ", loss=Loss." + enumName (c.loss) + ")";
}

/** The factory call that builds n, for the reprs: isotropic with its sigma (which it gives at any
  * point), so that a repr builds the same model back. */
std::string
noiseFactory (const SensorNoiseModel& n)
{
  switch (n.type ())
  {
    case SensorNoiseModel::Type::None: return "none()";
    case SensorNoiseModel::Type::Isotropic:
    {
      double axial = 0.0, lateral = 0.0;
      n.sigmas (Eigen::Vector3d::Zero (), Eigen::Vector3d::Zero (), SensorPose (), axial, lateral);
      return "isotropic(" + num (axial) + ")";
    }
    case SensorNoiseModel::Type::Anisotropic: return "anisotropic(...)";
    case SensorNoiseModel::Type::KinectV1: return "kinect()";
    case SensorNoiseModel::Type::Stereo: return "stereo()";
    case SensorNoiseModel::Type::Lidar: return "lidar()";
  }
  return "?";
}

/** \brief A CloudModel property reading one number of its surface model: NaN without one. */
auto
surfaceNumber (double (SurfaceModel::*member) () const)
{
  return [member] (const CloudModel& c) {
    return c.surface ().empty () ? std::numeric_limits<double>::quiet_NaN () : (c.surface ().*member) ();
  };
}

/** \brief A CloudModel property reading one flag of its surface model: None without one. */
auto
surfaceFlag (bool (SurfaceModel::*member) () const)
{
  return [member] (const CloudModel& c) -> py::object {
    return c.surface ().empty () ? py::none () : py::cast ((c.surface ().*member) ());
  };
}

/** A loaded cloud's x y z as an (N, 3) float32 array. */
template <typename PointT>
py::array_t<float>
pointsOf (const pcl::PointCloud<PointT>& cloud)
{
  py::array_t<float> points ({static_cast<py::ssize_t> (cloud.size ()), static_cast<py::ssize_t> (3)});
  auto p = points.mutable_unchecked<2> ();
  for (std::size_t i = 0; i < cloud.size (); ++i)
    for (int d = 0; d < 3; ++d)
      p (static_cast<py::ssize_t> (i), d) = cloud[i].data[d];
  return points;
}

/** A loaded cloud's VIEWPOINT as 7 numbers: tx ty tz qw qx qy qz. */
template <typename PointT>
py::array_t<double>
viewpointOf (const pcl::PointCloud<PointT>& cloud)
{
  py::array_t<double> viewpoint (7);
  double* v = viewpoint.mutable_data ();
  for (int d = 0; d < 3; ++d)
    v[d] = cloud.sensor_origin_[d];
  v[3] = cloud.sensor_orientation_.w ();
  v[4] = cloud.sensor_orientation_.x ();
  v[5] = cloud.sensor_orientation_.y ();
  v[6] = cloud.sensor_orientation_.z ();
  return viewpoint;
}

/** io::XyzRounding as read_cloud(rounding=True) returns it: (largest change, largest |coordinate|). */
py::tuple
roundingOf (const pcl_probcollision::io::XyzRounding& r)
{
  return py::make_tuple (r.largest_change, r.largest_magnitude);
}

/** The file as pcd_collision reads it: io::loadCloud (PCD, face-less PLY), NaN rows kept. */
py::tuple
readCloud (const std::filesystem::path& path, bool with_rounding)
{
  requireRegularFile (path);
  pcl::PointCloud<pcl::PointXYZ> cloud;
  pcl_probcollision::io::XyzRounding rounding;
  std::string error;
  bool loaded = false;
  {
    py::gil_scoped_release release;
    loaded = pcl_probcollision::io::loadCloud (path.string (), cloud, error, &rounding);
  }
  if (!loaded)
    throw py::value_error ("path: " + error);
  py::tuple read = py::make_tuple (pointsOf (cloud), viewpointOf (cloud), cloud.width, cloud.height);
  return with_rounding ? py::tuple (read + py::make_tuple (roundingOf (rounding))) : read;
}

/** read_cloud with the file's normal_x normal_y normal_z (io::loadCloudWithNormals, as pcd_collision
  * -surface reads them): (points, normals (N, 3) float32 as stored, NaN for none; None when the file
  * has no normals), viewpoint, width, height). */
py::tuple
readCloudWithNormals (const std::filesystem::path& path, bool with_rounding)
{
  requireRegularFile (path);
  pcl::PointCloud<pcl::PointNormal> cloud;
  bool has_normals = false;
  pcl_probcollision::io::XyzRounding rounding;
  std::string error;
  bool loaded = false;
  {
    py::gil_scoped_release release;
    loaded = pcl_probcollision::io::loadCloudWithNormals (path.string (), cloud, has_normals, error, &rounding);
  }
  if (!loaded)
    throw py::value_error ("path: " + error);
  const auto n = static_cast<py::ssize_t> (cloud.size ());
  py::object normals = py::none ();
  if (has_normals)
  {
    py::array_t<float> nrm ({n, static_cast<py::ssize_t> (3)});
    auto q = nrm.mutable_unchecked<2> ();
    for (py::ssize_t i = 0; i < n; ++i)
      for (int d = 0; d < 3; ++d)
        q (i, d) = cloud[static_cast<std::size_t> (i)].normal[d];
    normals = nrm;
  }
  py::tuple read = py::make_tuple (pointsOf (cloud), normals, viewpointOf (cloud), cloud.width, cloud.height);
  return with_rounding ? py::tuple (read + py::make_tuple (roundingOf (rounding))) : read;
}

pcl_probcollision::io::TriangleMesh
meshOf (const py::object& vertices_obj, const py::object& triangles_obj)
{
  auto V = py::array_t<double, py::array::forcecast>::ensure (vertices_obj);
  // Indices must be integers: a cast to int would truncate 1.9 to 1 and wrap 2^32 + 2 to 2
  // (found in review); read as 64-bit, so that the range check below sees the real value.
  const py::array raw = py::array::ensure (triangles_obj);
  if (raw && raw.size () > 0 && raw.dtype ().kind () != 'i' && raw.dtype ().kind () != 'u')
    throw py::type_error ("triangles: expected integer vertex indices, got dtype " +
                          py::str (raw.dtype ()).cast<std::string> ());
  auto F = py::array_t<std::int64_t, py::array::forcecast>::ensure (triangles_obj);
  if (!V || !F)
  {
    PyErr_Clear ();
    throw py::type_error ("expected numeric vertices (V, 3) and triangles (T, 3)");
  }
  if (V.ndim () != 2 || V.shape (1) != 3 || F.ndim () != 2 || F.shape (1) != 3)
    throw py::value_error ("expected vertices (V, 3) and triangles (T, 3), got " + shapeOf (V) + " and " + shapeOf (F));
  pcl_probcollision::io::TriangleMesh mesh;
  const auto v = V.unchecked<2> ();
  const auto f = F.unchecked<2> ();
  for (py::ssize_t i = 0; i < v.shape (0); ++i)
    mesh.vertices.push_back ({v (i, 0), v (i, 1), v (i, 2)});
  for (py::ssize_t i = 0; i < f.shape (0); ++i)
  {
    for (int d = 0; d < 3; ++d)
    {
      if (f (i, d) < 0 || f (i, d) >= v.shape (0))
        throw py::value_error ("triangles: row " + std::to_string (i) + " refers to a missing vertex");
      // A triangle's corners must be points the library takes (its coordinate range; a NaN
      // would read as a spacing problem in sample_mesh).
      const py::ssize_t j = static_cast<py::ssize_t> (f (i, d));
      for (int c = 0; c < 3; ++c)
        if (!(std::abs (v (j, c)) <= pcl_probcollision::detail::kMaxCoordinate))
          throw py::value_error ("vertices: row " + std::to_string (j) + " (a corner of triangle " + std::to_string (i) +
                                 ") is not finite or beyond the supported coordinate range of +-1e15");
    }
    mesh.triangles.push_back ({static_cast<int> (f (i, 0)), static_cast<int> (f (i, 1)), static_cast<int> (f (i, 2))});
  }
  return mesh;
}

/** The sampler's refusal of a spacing as a Python message: it names pcd_collision's flag, which
  * is `spacing` here. */
std::string
spacingError (const std::runtime_error& e)
{
  std::string why = e.what ();
  const std::string flag = "raise -mesh_density";
  if (const std::size_t at = why.find (flag); at != std::string::npos)
    why.replace (at, flag.size (), "raise spacing");
  return "spacing: " + why;
}

py::array_t<float>
cloudArray (const pcl::PointCloud<pcl::PointXYZ>& cloud)
{
  py::array_t<float> points ({static_cast<py::ssize_t> (cloud.size ()), static_cast<py::ssize_t> (3)});
  auto p = points.mutable_unchecked<2> ();
  for (std::size_t i = 0; i < cloud.size (); ++i)
    for (int d = 0; d < 3; ++d)
      p (static_cast<py::ssize_t> (i), d) = cloud[i].data[d];
  return points;
}

/** Poses as (M, 6) tx ty tz roll pitch yaw. */
py::array_t<double>
poseRows (const std::vector<pcd_collision::Pose>& poses)
{
  py::array_t<double> out ({static_cast<py::ssize_t> (poses.size ()), static_cast<py::ssize_t> (6)});
  auto o = out.mutable_unchecked<2> ();
  for (std::size_t k = 0; k < poses.size (); ++k)
    for (int d = 0; d < 6; ++d)
      o (static_cast<py::ssize_t> (k), d) = poses[k][static_cast<std::size_t> (d)];
  return out;
}

/** pcd_collision's -poses file (pcd_collision::parsePoses, the one reader of the format) as (M, 6)
  * tx ty tz roll pitch yaw. */
py::array_t<double>
readPoses (const std::filesystem::path& path)
{
  requireRegularFile (path);
  std::vector<pcd_collision::Pose> poses;
  std::string error = pcl_probcollision::io::unreadableFile (path.string ());
  std::ifstream f (path);
  if (!error.empty () || !pcd_collision::parsePoses (f, path.string (), poses, error))
    throw py::value_error ("path: " + error);
  return poseRows (poses);
}

/** The text of a -poses file (pcd_collision -poses -'s standard input) as readPoses reads a file,
  * its messages naming `name` for the file. */
py::array_t<double>
parsePoses (const py::bytes& text, const std::string& name)
{
  std::istringstream in (std::string (text), std::ios::binary);
  std::vector<pcd_collision::Pose> poses;
  std::string error;
  if (!pcd_collision::parsePoses (in, name, poses, error))
    throw py::value_error ("text: " + error);
  return poseRows (poses);
}

/** (M, 6) tx ty tz roll pitch yaw -> (M, 4, 4), by pcd_collision's rule (poseTransform). */
py::array_t<double>
posesFromXyzRpy (const py::object& obj)
{
  const auto a = realArray (obj, "poses", "a numeric array of shape (M, 6)");
  if (a.ndim () != 2 || a.shape (1) != 6)
    throw py::value_error ("poses: expected shape (M, 6), got " + shapeOf (a));
  const auto p = a.unchecked<2> ();
  py::array_t<double> out ({a.shape (0), static_cast<py::ssize_t> (4), static_cast<py::ssize_t> (4)});
  auto o = out.mutable_unchecked<3> ();
  for (py::ssize_t k = 0; k < p.shape (0); ++k)
  {
    const pcd_collision::Pose pose = {p (k, 0), p (k, 1), p (k, 2), p (k, 3), p (k, 4), p (k, 5)};
    // The rule of pcd_collision's -pose and read_poses: a NaN or a translation out of range is no pose.
    if (const std::string why = pcd_collision::poseValueError (pose); !why.empty ())
      throw py::value_error ("poses[" + std::to_string (k) + "]: " + why);
    const Eigen::Isometry3d T = pcd_collision::poseTransform (pose);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        o (k, i, j) = T.matrix () (i, j);
  }
  return out;
}

/** (M, 4, 4) rigid transforms -> their inverses, as Eigen::Isometry3d::inverse() computes them. */
py::array_t<double>
invertPoses (const py::object& obj)
{
  const auto a = poseArray (obj);
  const auto p = a.unchecked<3> ();
  py::array_t<double> out ({a.shape (0), static_cast<py::ssize_t> (4), static_cast<py::ssize_t> (4)});
  auto o = out.mutable_unchecked<3> ();
  for (py::ssize_t k = 0; k < p.shape (0); ++k)
  {
    // Rigid, as collide() checks: Eigen's isometry inverse transposes the rotation, which for a
    // scaled or sheared matrix is no inverse at all.
    const Eigen::Isometry3d inv = poseAt (p, k, true).inverse ();
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        o (k, i, j) = inv.matrix () (i, j);
  }
  return out;
}
/** \brief What pcd_collision's parser makes of its flags (without the inputs); ValueError with its
  * usage error. */
pcd_collision::Options
optionsOfFlags (const std::vector<std::string>& flags)
{
  std::vector<std::string> args{"a.pcd", "b.pcd"};
  args.insert (args.end (), flags.begin (), flags.end ());
  pcd_collision::ParseResult r = pcd_collision::parseCommandLine (args);
  if (r.kind != pcd_collision::ParseResult::Kind::Run)
    throw py::value_error (r.error);
  return std::move (r.options);
}

/** \brief pcd_collision_json_lines: pcd_collision's JSON lines (tools/result_json.h) for answers
  * held as columns (the Dask layer's BatchResults.fields). */
std::vector<std::string>
pcdCollisionJsonLines (const std::vector<std::string>& flags, const py::dict& input_a, const py::dict& input_b,
                       const py::dict& fields, const py::object& poses, double build_ms)
{
  const pcd_collision::Options options = optionsOfFlags (flags);
  const auto summary = [] (const py::dict& d, const char* name) {
    pcd_collision::InputSummary s;
    const auto get = [&] (const char* key) -> py::object {
      if (!d.contains (key))
        throw py::key_error (std::string (name) + ": missing '" + key + "'");
      return d[key];
    };
    s.path = get ("path").cast<std::string> ();
    s.mesh = get ("kind").cast<std::string> () == "mesh";
    s.points = get ("points").cast<std::size_t> ();
    s.load_ms = get ("load_ms").cast<double> ();
    if (s.mesh)
    {
      s.vertices = get ("vertices").cast<std::size_t> ();
      s.triangles = get ("triangles").cast<std::size_t> ();
      s.spacing = get ("spacing").cast<double> ();
      s.spacing_source = get ("spacing_source").cast<std::string> ();
      s.sample_ms = get ("sample_ms").cast<double> ();
    }
    else
    {
      s.finite = get ("finite").cast<std::size_t> ();
      s.width = get ("width").cast<std::uint64_t> ();
      s.height = get ("height").cast<std::uint64_t> ();
    }
    if (!get ("merged_samples").is_none ())
      s.merged_samples = get ("merged_samples").cast<std::size_t> ();
    if (const py::object f = get ("surface"); !f.is_none ())
    {
      const py::dict facts = f.cast<py::dict> ();
      s.surface = pcd_collision::SurfaceFacts{facts["orientation"].cast<std::string> (), facts["inside_known"].cast<bool> (),
                                              facts["hidden_from_viewpoint"].cast<double> (),
                                              facts["closed_share"].cast<double> (), facts["solid_share"].cast<double> ()};
    }
    return s;
  };
  const pcd_collision::InputSummary a = summary (input_a, "input_a"), b = summary (input_b, "input_b");
  const auto rows = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure (poses);
  if (!rows || rows.ndim () != 2 || rows.shape (1) != 6)
    throw py::value_error ("poses: expected shape (M, 6)");
  const std::size_t m = static_cast<std::size_t> (rows.shape (0));
  // One column a member, m rows (of width values).
  const auto column = [&] (const char* key, py::ssize_t width = 1) {
    if (!fields.contains (key))
      throw py::key_error (std::string ("fields: missing '") + key + "'");
    auto c = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure (fields[key]);
    if (!c || c.size () != static_cast<py::ssize_t> (m) * width)
      throw py::value_error (std::string ("fields['") + key + "']: expected " + std::to_string (m) + " rows of " +
                             std::to_string (width));
    return c;
  };
  const auto probability = column ("probability"), verdict = column ("verdict"), answered_by = column ("answered_by"),
             signed_distance = column ("signed_distance"), signed_distance_std = column ("signed_distance_std"),
             unobserved = column ("unobserved"), sample_distance = column ("sample_distance"),
             nearest_a = column ("nearest_point_a", 3), nearest_b = column ("nearest_point_b", 3),
             lower_bound = column ("lower_bound"), budget_exhausted = column ("budget_exhausted"),
             full_resolution = column ("full_resolution"), no_leaf_tested = column ("no_leaf_tested"),
             points_a = column ("points_a"), points_b = column ("points_b"),
             skipped = column ("points_skipped_nonfinite"), leaf_pairs = column ("leaf_pairs_tested"),
             bv_tests = column ("bv_tests"), kernel_pairs = column ("kernel_leaf_pairs"),
             degenerate_pairs = column ("degenerate_leaf_pairs"), iterations = column ("classifier_iterations"),
             query_ms = column ("query_ms"), witness_side = column ("witness_side"),
             witness_index = column ("witness_index"), witness_point = column ("witness_point", 3),
             witness_normal = column ("witness_normal", 3);
  const auto count = [] (double v) { return static_cast<std::size_t> (v); };
  const auto vector3 = [] (const py::array_t<double, py::array::c_style | py::array::forcecast>& c, std::size_t i) {
    const double* v = c.data () + 3 * i;
    return Eigen::Vector3d (v[0], v[1], v[2]);
  };
  std::vector<std::string> lines;
  lines.reserve (m);
  const std::string run_members = pcd_collision::runMembersJson (options, a, b);  // the same in every line
  for (std::size_t i = 0; i < m; ++i)
  {
    CollisionResult r;
    r.status = CollisionResult::Status::Ok;
    r.probability = probability.at (i);
    r.verdict = static_cast<Verdict> (static_cast<int> (verdict.at (i)));
    r.answered_by = static_cast<AnsweredBy> (static_cast<int> (answered_by.at (i)));
    r.signed_distance = signed_distance.at (i);
    r.signed_distance_std = signed_distance_std.at (i);
    r.unobserved = unobserved.at (i) != 0.0;
    r.sample_distance = sample_distance.at (i) != 0.0;
    r.nearest_point_a = vector3 (nearest_a, i);
    r.nearest_point_b = vector3 (nearest_b, i);
    r.lower_bound = lower_bound.at (i) != 0.0;
    r.budget_exhausted = budget_exhausted.at (i) != 0.0;
    r.full_resolution = full_resolution.at (i) != 0.0;
    r.no_leaf_tested = no_leaf_tested.at (i) != 0.0;
    r.points_a = count (points_a.at (i));
    r.points_b = count (points_b.at (i));
    r.points_skipped_nonfinite = count (skipped.at (i));
    r.leaf_pairs_tested = count (leaf_pairs.at (i));
    r.bv_tests = count (bv_tests.at (i));
    r.kernel_leaf_pairs = count (kernel_pairs.at (i));
    r.degenerate_leaf_pairs = count (degenerate_pairs.at (i));
    r.classifier_iterations = count (iterations.at (i));
    r.build_ms = i == 0 ? build_ms : 0.0;  // the models are built once: the first pose's
    r.query_ms = query_ms.at (i);
    r.witness_side = static_cast<int> (witness_side.at (i));
    r.witness_index = static_cast<int> (witness_index.at (i));
    r.witness_point = vector3 (witness_point, i);
    r.witness_normal = vector3 (witness_normal, i);
    const pcd_collision::Pose pose{rows.at (i, 0), rows.at (i, 1), rows.at (i, 2), rows.at (i, 3), rows.at (i, 4), rows.at (i, 5)};
    lines.push_back (pcd_collision::resultJson (options, a, b, r, pose, static_cast<long long> (i), std::nullopt, 0, &run_members));
  }
  return lines;
}
} // namespace

PYBIND11_MODULE (_core, m)
{
  m.doc () = "Probabilistic collision checking between noisy point clouds (pcl_probcollision's C++ core).\n\n"
             "Build a CloudModel per cloud once (build_model from numpy, load_model from a .pcd file), then\n"
             "query pairs with collide(a, b, pose) or collide_batch(a, b, poses). Defaults are the C++ ones.";

  py::register_exception_translator ([] (std::exception_ptr p) {
    try
    {
      if (p)
        std::rethrow_exception (p);
    }
    catch (const pcl::BadArgumentException& e)
    {
      PyErr_SetString (PyExc_ValueError, utf8Text (errorMessage (e)).c_str ());
    }
    catch (const pcl::IOException& e)
    {
      PyErr_SetString (PyExc_OSError, utf8Text (errorMessage (e)).c_str ());
    }
    catch (const pcl::PCLException& e)
    {
      PyErr_SetString (PyExc_RuntimeError, utf8Text (errorMessage (e)).c_str ());
    }
  });
  // Every ValueError of this module's functions: a message naming a path that is not UTF-8 (the
  // readers' "path: ..." messages) keeps it as \xNN escapes; pybind11's own translation made it
  // an empty ValueError. Local: other pybind11 modules' exceptions are theirs.
  py::register_local_exception_translator ([] (std::exception_ptr p) {
    try
    {
      if (p)
        std::rethrow_exception (p);
    }
    catch (const py::value_error& e)
    {
      PyErr_SetString (PyExc_ValueError, utf8Text (e.what ()).c_str ());
    }
  });

  py::enum_<Verdict> (m, "Verdict", "The three-way decision: P < free_below is Free, P > collision_above InCollision, "
                                    "anything between InContact; Unknown when the query failed.")
      .value ("Unknown", Verdict::Unknown)
      .value ("Free", Verdict::Free)
      .value ("InContact", Verdict::InContact)
      .value ("InCollision", Verdict::InCollision);

  py::enum_<AnsweredBy> (m, "AnsweredBy", "Whose answer a result's probability is: Separators (the paper's leaf-pair "
                                          "classifiers), SurfaceLayer, or Pooled (the mean of both); with "
                                          "request.surface_ladder it varies from pose to pose. Unknown when the query failed.")
      .value ("Unknown", AnsweredBy::Unknown)
      .value ("Separators", AnsweredBy::Separators)
      .value ("SurfaceLayer", AnsweredBy::SurfaceLayer)
      .value ("Pooled", AnsweredBy::Pooled);

  py::enum_<TraversalMode> (m, "TraversalMode", "How the traversal treats node pairs whose boxes are disjoint.")
      .value ("ExpectedWeight", TraversalMode::ExpectedWeight)
      .value ("Stochastic", TraversalMode::Stochastic)
      .value ("ExpandedBV", TraversalMode::ExpandedBV);

  py::enum_<NormalOrientation> (m, "NormalOrientation",
      "Where the surface model's normals get their orientation (which side is outside); CloudModelParams.orientation.\n\n"
      "Auto (default): the points' own normals when build_model() was given finite ones (a mesh's faces) or\n"
      "    load_model() read them from the file, else the viewpoint when it lies outside the cloud's bounding box\n"
      "    and sees it as one scan does (at most 10 % of the points hidden behind others from there), else Propagate.\n"
      "PointNormals: the given normals, taken as outward; points without one are oriented from their neighbours\n"
      "    (none given at all: Propagate).\n"
      "Viewpoint: toward the sensor origin (the viewpoint); grazing points (|cos| < 0.2) from their neighbours;\n"
      "    a viewpoint that sees the cloud edge-on, or not as one scan does (a closed object's far side facing it\n"
      "    from behind), orients nothing: Propagate (CloudModel.surface_orientation says so).\n"
      "Propagate: propagated over the neighbour graph from the point farthest from the centroid, then each\n"
      "    connected part flipped so that its enclosed volume is positive (closed objects). Not trusted to say\n"
      "    where the inside is (an open sheet, a room seen from within): the surface layer takes it as two-sided.")
      .value ("Auto", NormalOrientation::Auto)
      .value ("PointNormals", NormalOrientation::PointNormals)
      .value ("Viewpoint", NormalOrientation::Viewpoint)
      .value ("Propagate", NormalOrientation::Propagate);

  // --- SensorNoiseModel -------------------------------------------------------------------------
  py::class_<SensorNoiseModel> noise (m, "SensorNoiseModel",
      "Sensor (position) noise added to the estimated covariances. Build with none(), isotropic(sigma), "
      "kinect(), stereo() or lidar() (default parameters), or from_name(name, sigma).");
  noise.def (py::init<> (), "No sensor noise (the default).")
      .def_static ("none", [] { return SensorNoiseModel (); }, "No sensor noise (the default).")
      .def_static ("isotropic", &SensorNoiseModel::isotropic, py::arg ("sigma"),
                   "sigma^2 I, sigma >= 0 in data units (ValueError otherwise).")
      .def_static ("kinect", [] { return SensorNoiseModel::kinect (); }, "Kinect v1 (Nguyen et al. 2012), metres; "
                   "needs the sensor pose (a numpy cloud's viewpoint is the origin looking along +z).")
      .def_static ("stereo", [] { return SensorNoiseModel::stereo (); }, "Stereo triangulation (PR2-like defaults), metres.")
      .def_static ("lidar", [] { return SensorNoiseModel::lidar (); }, "Lidar: range and angular sigma, metres.")
      .def_static ("from_name", &SensorNoiseModel::fromName, py::arg ("name"),
                   py::arg ("sigma") = SensorNoiseModel::kDefaultIsotropicSigma,
                   "'none', 'isotropic', 'kinect', 'stereo' or 'lidar' with default parameters (isotropic uses sigma).")
      .def_property_readonly ("name", [] (const SensorNoiseModel& n) { return std::string (n.name ()); })
      .def_property_readonly ("uses_sensor_pose", &SensorNoiseModel::usesSensorPose)
      .def ("__repr__", [] (const SensorNoiseModel& n) {
        return std::string ("SensorNoiseModel.") + noiseFactory (n);
      });

  // --- CloudModelParams ---------------------------------------------------------------------------
  const CloudModelParams dp;
  py::class_<CloudModelParams> (m, "CloudModelParams",
      "How a CloudModel is built from a point cloud (the per-cloud settings).\n\n"
      "k: neighbours of the covariance estimation (>= 1); noise: SensorNoiseModel added to the covariances;\n"
      "surface_projection: locally denoised positions; n_max, n_min, sigma_max, epsilon, k_sigma, split, noise_stop,\n"
      "n_noise_max, leakage_bound: the hierarchy (BVHParams);\n"
      "surface: also build the oriented surface model (METHOD.md 10a) that CollisionRequest.surface queries\n"
      "(experimental, issue #16; costs a normal fit and an orientation pass per point); orientation: how its\n"
      "normals are oriented (NormalOrientation, default Auto); closed_objects: the cloud samples closed solids,\n"
      "so a propagated orientation, once checked by the winding number, says where the inside is.")
      .def (py::init ([] (int k, const SensorNoiseModel& noise, bool surface_projection, int n_max, std::optional<int> n_min,
                          double sigma_max, double epsilon, double k_sigma, bool surface, NormalOrientation orientation,
                          bool closed_objects, const ThreadsArg& threads, std::optional<double> noise_resolution, const std::string& noise_resolution_gate,
                          bool keep_full_resolution, double noise_stop, const std::string& split, int n_noise_max,
                          const std::string& leakage_bound) {
              CloudModelParams p;
              p.k = k;
              p.noise = noise;
              p.surface_projection = surface_projection;
              p.surface = surface;
              p.orientation = orientation;
              p.closed_objects = closed_objects;
              p.hierarchy.n_max = n_max;
              // As pcd_collision's -nmax (BVHParams::nMinFor, the one rule): n_min follows a smaller
              // n_max unless given.
              p.hierarchy.n_min = n_min ? *n_min : BVHParams::nMinFor (n_max);
              p.hierarchy.sigma_max = sigma_max;
              p.hierarchy.epsilon = epsilon;
              p.hierarchy.k_sigma = k_sigma;
              p.threads = checkThreads (threads);
              p.noise_resolution = noise_resolution;
              setResolutionGate (p, noise_resolution_gate);
              p.keep_full_resolution = keep_full_resolution;
              p.hierarchy.noise_stop = noise_stop;
              setSplit (p, split);
              p.hierarchy.n_noise_max = n_noise_max;
              setLeakage (p, leakage_bound);
              return p;
            }),
            py::kw_only (), py::arg ("k") = dp.k, py::arg_v ("noise", dp.noise, "SensorNoiseModel.none()"),
            py::arg ("surface_projection") = dp.surface_projection, py::arg ("n_max") = dp.hierarchy.n_max,
            py::arg_v ("n_min", py::none (), "min(8, n_max)"), py::arg ("sigma_max") = dp.hierarchy.sigma_max,
            py::arg ("epsilon") = dp.hierarchy.epsilon, py::arg ("k_sigma") = dp.hierarchy.k_sigma,
            py::arg ("surface") = dp.surface, py::arg ("orientation") = dp.orientation,
            py::arg ("closed_objects") = dp.closed_objects, py::arg ("threads") = dp.threads,
            py::arg_v ("noise_resolution", dp.noise_resolution, "None"),
            py::arg ("noise_resolution_gate") = std::string (CloudModelParams::resolutionGateName (dp.noise_resolution_gate)),
            py::arg ("keep_full_resolution") = dp.keep_full_resolution, py::arg ("noise_stop") = dp.hierarchy.noise_stop,
            py::arg ("split") = splitName (dp), py::arg ("n_noise_max") = dp.hierarchy.n_noise_max,
            py::arg ("leakage_bound") = leakageName (dp),
            "Every argument defaults to the C++ CloudModelParams default, n_min to min(8, n_max) as pcd_collision's\n"
            "-nmax sets it. Each is also an attribute.")
      .def_readwrite ("k", &CloudModelParams::k)
      .def_readwrite ("noise", &CloudModelParams::noise)
      .def_readwrite ("surface_projection", &CloudModelParams::surface_projection)
      .def_readwrite ("surface", &CloudModelParams::surface,
                      "Build the surface model CollisionRequest.surface queries (default False).")
      .def_readwrite ("orientation", &CloudModelParams::orientation,
                      "How the surface model's normals are oriented (NormalOrientation, default Auto).")
      .def_readwrite ("closed_objects", &CloudModelParams::closed_objects,
                      "The cloud samples closed solids (not an open sheet, one scan's view or a room seen from\n"
                      "within): a propagated orientation is checked by the winding number and, where it checks out,\n"
                      "says where the inside is (CloudModel.surface_inside_known). Default False: a propagated surface\n"
                      "is two-sided.")
      .def_readwrite ("noise_resolution", &CloudModelParams::noise_resolution,
                      "Merge samples closer than this many sensor-noise sigmas into one (issue #17), where\n"
                      "noise_resolution_gate lets them; 0: never. None (default): 2 without the surface model, 0\n"
                      "with it (noise_resolution_applied), where the default gate still merges a depth scan's dense\n"
                      "samples at 2 (CloudModel.params gives the radius applied).")
      .def_property_readonly ("noise_resolution_applied", &CloudModelParams::noiseResolution,
                              "The merge radius the build applies to a whole cloud (C++ noiseResolution()):\n"
                              "noise_resolution when set, else 2 without the surface model and 0 with it.")
      .def_property (
        "noise_resolution_gate",
        [] (const CloudModelParams& p) { return std::string (CloudModelParams::resolutionGateName (p.noise_resolution_gate)); },
        &setResolutionGate,
        "Where noise_resolution merges (pcd_collision's -noise_resolution_gate): 'everywhere' (every sample),\n"
        "'spacing' (only samples spaced within their noise sigma) or 'cloud' (the whole cloud where it is\n"
        "sampled finer than its noise, else the samples spaced within their noise where most samples are\n"
        "twice as dense as it, as a depth scan's near objects before a sparse far wall, else nothing).\n"
        "Default: CloudModelParams' ('cloud').")
      .def_property ("noise_resolution_gated",
                     [] (const CloudModelParams& p) {
                       return p.noise_resolution_gate == CloudModelParams::ResolutionGate::WhereNoiseExceedsSpacing;
                     },
                     [] (CloudModelParams& p, bool v) {
                       p.noise_resolution_gate = v ? CloudModelParams::ResolutionGate::WhereNoiseExceedsSpacing
                                                   : CloudModelParams::ResolutionGate::Everywhere;
                     },
                     "noise_resolution_gate == 'spacing'; setting False sets 'everywhere'.")
      .def_property ("noise_resolution_whole_cloud",
                     [] (const CloudModelParams& p) {
                       return p.noise_resolution_gate == CloudModelParams::ResolutionGate::WholeCloud;
                     },
                     [] (CloudModelParams& p, bool v) {
                       p.noise_resolution_gate = v ? CloudModelParams::ResolutionGate::WholeCloud
                                                   : CloudModelParams::ResolutionGate::Everywhere;
                     },
                     "noise_resolution_gate == 'cloud'; setting False sets 'everywhere'.")
      .def_readwrite ("keep_full_resolution", &CloudModelParams::keep_full_resolution,
                      "Where noise_resolution merged samples, also keep the unmerged model: the separators' contact\n"
                      "leaning to collision (P >= 0.5) is asked again at full resolution within 256 leaf-pair fits,\n"
                      "and its collision stands (CollisionResult.full_resolution). Default True.")
      .def_property ("threads", [] (const CloudModelParams& p) { return p.threads; },
                     [] (CloudModelParams& p, const ThreadsArg& v) { p.threads = checkThreads (v); },
                     "Threads of the build (covariance estimation and hierarchy), in [0, MAX_THREADS]; default 0:\n"
                     "one per hardware thread. The model is the same for any count. ValueError outside that range,\n"
                     "as pcd_collision refuses -threads.")
      .def_property ("n_max", [] (const CloudModelParams& p) { return p.hierarchy.n_max; },
                     [] (CloudModelParams& p, int v) { p.hierarchy.n_max = v; },
                     "A hierarchy node with more points is split (>= 1; default 20). Setting it leaves n_min as it is:\n"
                     "below n_min, set n_min too (validate() and build_model say so); the constructor's n_max sets\n"
                     "n_min to min(8, n_max) unless given, as pcd_collision's -nmax.")
      .def_property ("n_min", [] (const CloudModelParams& p) { return p.hierarchy.n_min; },
                     [] (CloudModelParams& p, int v) { p.hierarchy.n_min = v; },
                     "A hierarchy node of at most n_min points is never split (1 <= n_min <= n_max; default 8).")
      .def_property ("sigma_max", [] (const CloudModelParams& p) { return p.hierarchy.sigma_max; },
                     [] (CloudModelParams& p, double v) { p.hierarchy.sigma_max = v; })
      .def_property ("epsilon", [] (const CloudModelParams& p) { return p.hierarchy.epsilon; },
                     [] (CloudModelParams& p, double v) { p.hierarchy.epsilon = v; })
      .def_property ("k_sigma", [] (const CloudModelParams& p) { return p.hierarchy.k_sigma; },
                     [] (CloudModelParams& p, double v) { p.hierarchy.k_sigma = v; })
      .def_property ("noise_stop", [] (const CloudModelParams& p) { return p.hierarchy.noise_stop; },
                     [] (CloudModelParams& p, double v) { p.hierarchy.noise_stop = v; },
                     "Do not split a hierarchy node of at most n_noise_max points whose extent is within\n"
                     "noise_stop noise standard deviations (BVHParams::noise_stop); default 0: off.")
      .def_property ("split", &splitName, &setSplit,
                     "Hierarchy split style, 'pca' (default) or 'octree' (pcd_collision's -split).")
      .def_property ("n_noise_max", [] (const CloudModelParams& p) { return p.hierarchy.n_noise_max; },
                     [] (CloudModelParams& p, int v) { p.hierarchy.n_noise_max = v; },
                     "Largest hierarchy node noise_stop may keep whole (>= 1; default 160): bounds a leaf's points\n"
                     "(BVHParams::n_noise_max).")
      .def_property ("leakage_bound", &leakageName, &setLeakage,
                     "How a box's three slab probabilities combine into a point's outside probability\n"
                     "(BVHParams::leakage_bound): 'min_slab' (default, METHOD.md 8.4, a lower bound) or 'union_bound'\n"
                     "(an upper bound).")
      .def ("validate", &CloudModelParams::validate, "Raises ValueError naming the first member out of range.")
      .def ("__repr__", [] (const CloudModelParams& p) {
        return "CloudModelParams(k=" + std::to_string (p.k) + ", noise=SensorNoiseModel." + noiseFactory (p.noise) +
               ", surface_projection=" + (p.surface_projection ? "True" : "False") +
               ", n_max=" + std::to_string (p.hierarchy.n_max) + ", n_min=" + std::to_string (p.hierarchy.n_min) +
               ", sigma_max=" + num (p.hierarchy.sigma_max) + ", epsilon=" + num (p.hierarchy.epsilon) +
               ", k_sigma=" + num (p.hierarchy.k_sigma) + ", surface=" + (p.surface ? "True" : "False") +
               ", orientation=NormalOrientation." + enumName (p.orientation) +
               ", closed_objects=" + (p.closed_objects ? "True" : "False") + ", threads=" + std::to_string (p.threads) +
               ", noise_resolution=" + (p.noise_resolution ? num (*p.noise_resolution) : std::string ("None")) +
               ", noise_resolution_gate='" +
               CloudModelParams::resolutionGateName (p.noise_resolution_gate) + "', keep_full_resolution=" +
               (p.keep_full_resolution ? "True" : "False") + ", noise_stop=" + num (p.hierarchy.noise_stop) +
               ", split='" + splitName (p) + "', n_noise_max=" + std::to_string (p.hierarchy.n_noise_max) +
               ", leakage_bound='" + leakageName (p) + "')";
      });

  // --- ClassifierParams ---------------------------------------------------------------------------
  py::enum_<KernelMode> (m, "KernelMode", "Which separating surface a leaf pair fits (METHOD.md 5.7); ClassifierParams.kernel.")
      .value ("Linear", KernelMode::Linear)
      .value ("RFF", KernelMode::RFF)
      .value ("Ladder", KernelMode::Ladder);
  py::enum_<TrainingMode> (m, "TrainingMode", "How the covariances enter training (METHOD.md 5.2); ClassifierParams.training.")
      .value ("Standard", TrainingMode::Standard)
      .value ("Robust", TrainingMode::Robust);
  py::enum_<Loss> (m, "Loss", "The loss on the margin violation (METHOD.md 5.3); ClassifierParams.loss.")
      .value ("SquaredHinge", Loss::SquaredHinge)
      .value ("Huber", Loss::Huber);
  const ClassifierParams dcl;
  py::class_<ClassifierParams> (m, "ClassifierParams",
      "The leaf-pair classifier of the separators (METHOD.md 5.7); CollisionRequest.classifier. Lengths are in\n"
      "the unit-cube frame of the problem, so they do not depend on units.\n\n"
      "kernel: Linear (a plane), RFF (random Fourier features) or Ladder (default: the plane first, the kernel\n"
      "rungs where it misclassifies); training: Robust (default, the chance-constrained SVM) or Standard\n"
      "(covariances for the probabilities only); confidence: kappa in (0.5, 1); gamma_cap: eta in (0, 1);\n"
      "C > 0: the soft-margin weight (default 1000, not the paper's 10: docs/RESULTS.md, 'C10'); rbf_gamma > 0;\n"
      "rff_features >= 8 and rff_features_large >= rff_features: the kernel rungs' D; rff_seed;\n"
      "ladder_depth_sigmas > 0 and ladder_fraction in [0, 1): when the ladder escalates;\n"
      "exact_points_in_maximum: whether noise-free points take part in the maximum; max_iterations >= 1;\n"
      "loss: SquaredHinge (default) or Huber.")
      .def (py::init ([] (KernelMode kernel, TrainingMode training, double confidence, double gamma_cap, double C,
                          double rbf_gamma, int rff_features, int rff_features_large, std::uint64_t rff_seed,
                          double ladder_depth_sigmas, double ladder_fraction, bool exact_points_in_maximum,
                          int max_iterations, Loss loss) {
              ClassifierParams c;
              c.kernel = kernel;
              c.training = training;
              c.confidence = confidence;
              c.gamma_cap = gamma_cap;
              c.C = C;
              c.rbf_gamma = rbf_gamma;
              c.rff_features = rff_features;
              c.rff_features_large = rff_features_large;
              c.rff_seed = rff_seed;
              c.ladder_depth_sigmas = ladder_depth_sigmas;
              c.ladder_fraction = ladder_fraction;
              c.exact_points_in_maximum = exact_points_in_maximum;
              c.max_iterations = max_iterations;
              c.loss = loss;
              return c;
            }),
            py::kw_only (), py::arg ("kernel") = dcl.kernel, py::arg ("training") = dcl.training,
            py::arg ("confidence") = dcl.confidence, py::arg ("gamma_cap") = dcl.gamma_cap, py::arg ("C") = dcl.C,
            py::arg ("rbf_gamma") = dcl.rbf_gamma, py::arg ("rff_features") = dcl.rff_features,
            py::arg ("rff_features_large") = dcl.rff_features_large, py::arg ("rff_seed") = dcl.rff_seed,
            py::arg ("ladder_depth_sigmas") = dcl.ladder_depth_sigmas, py::arg ("ladder_fraction") = dcl.ladder_fraction,
            py::arg ("exact_points_in_maximum") = dcl.exact_points_in_maximum,
            py::arg ("max_iterations") = dcl.max_iterations, py::arg ("loss") = dcl.loss,
            "Every argument defaults to the C++ ClassifierParams default; validate() (or the query) checks the ranges.")
      .def_readwrite ("kernel", &ClassifierParams::kernel)
      .def_readwrite ("training", &ClassifierParams::training)
      .def_readwrite ("confidence", &ClassifierParams::confidence)
      .def_readwrite ("gamma_cap", &ClassifierParams::gamma_cap)
      .def_readwrite ("C", &ClassifierParams::C)
      .def_readwrite ("rbf_gamma", &ClassifierParams::rbf_gamma)
      .def_readwrite ("rff_features", &ClassifierParams::rff_features)
      .def_readwrite ("rff_features_large", &ClassifierParams::rff_features_large)
      .def_readwrite ("rff_seed", &ClassifierParams::rff_seed)
      .def_readwrite ("ladder_depth_sigmas", &ClassifierParams::ladder_depth_sigmas)
      .def_readwrite ("ladder_fraction", &ClassifierParams::ladder_fraction)
      .def_readwrite ("exact_points_in_maximum", &ClassifierParams::exact_points_in_maximum)
      .def_readwrite ("max_iterations", &ClassifierParams::max_iterations)
      .def_readwrite ("loss", &ClassifierParams::loss)
      .def ("validate", &ClassifierParams::validate, "Raises ValueError naming the first parameter out of range.")
      .def ("__eq__", [] (const ClassifierParams& a, const ClassifierParams& b) { return a == b; })
      .def ("__repr__", [] (const ClassifierParams& c) { return classifierRepr (c); });

  // --- CollisionRequest ---------------------------------------------------------------------------
  const CollisionRequest dr;
  py::class_<CollisionRequest> (m, "CollisionRequest",
      "What a collision query computes and how. P < free_below is Free, P > collision_above InCollision.\n\n"
      "exhaustive: visit every reachable leaf pair instead of stopping once P > collision_above;\n"
      "per_point: fill probabilities_a/_b; enable_timings: fill build_ms/query_ms; traversal, rho_min, seed,\n"
      "expanded_k_sigma: the traversal (TraversalMode); defer_kernel_fits: the ladder classifier;\n"
      "max_leaf_fits: at most this many leaf pairs tested a query, nearest first (0 = no cap; result.budget_exhausted);\n"
      "max_surface_pairs: with surface, the surface layer's cap, about this many leaf pairs a query (0 = no cap;\n"
      "result.budget_exhausted; ValueError without surface);\n"
      "surface: the surface layer (experimental, issue #16): each object's points tested against the other's\n"
      "oriented surface, filling CollisionResult.signed_distance; needs both models built with\n"
      "CloudModelParams(surface=True), otherwise the separators answer and signed_distance stays NaN;\n"
      "surface_pooled, surface_ladder, surface_calibrated: each needs surface (ValueError without it; pcd_collision's\n"
      "-surface_pooled and -surface_ladder imply -surface);\n"
      "surface_pooled: with surface, the mean of the surface layer's P and the separators' (experimental);\n"
      "surface_ladder: with surface, the separators first and the surface layer only where they leave the answer\n"
      "open (experimental; excludes surface_pooled);\n"
      "surface_calibrated: with surface, P in [0.1, 0.9] through the calibration map fitted on the evaluation's\n"
      "procedural scenes (default False: the model's raw P);\n"
      "distance: beyond the query's reach, signed_distance is the distance between the nearest samples\n"
      "(CollisionResult.sample_distance, nearest_point_a/_b), as FCL's distance request; near contact\n"
      "the surface layer's signed_distance is then an estimate, never the first deciding point's bound\n"
      "(with surface_ladder also where the separators find a sure collision; their P stands);\n"
      "classifier: the separators' leaf-pair classifier (ClassifierParams; default: the C++ defaults).")
      .def (py::init ([] (double free_below, double collision_above, bool exhaustive, bool per_point,
                          bool enable_timings, TraversalMode traversal, double rho_min, std::uint64_t seed,
                          double expanded_k_sigma, bool defer_kernel_fits, std::size_t max_leaf_fits,
                          std::size_t max_surface_pairs, bool surface,
                          bool surface_pooled, bool surface_ladder, bool surface_calibrated, bool distance,
                          const ClassifierParams& classifier) {
              CollisionRequest r;
              r.free_below = free_below;
              r.collision_above = collision_above;
              r.exhaustive = exhaustive;
              r.per_point = per_point;
              r.enable_timings = enable_timings;
              r.traversal = traversal;
              r.rho_min = rho_min;
              r.seed = seed;
              r.expanded_k_sigma = expanded_k_sigma;
              r.defer_kernel_fits = defer_kernel_fits;
              r.max_leaf_fits = max_leaf_fits;
              r.max_surface_pairs = max_surface_pairs;
              r.surface = surface;
              r.surface_pooled = surface_pooled;
              r.surface_ladder = surface_ladder;
              r.surface_calibrated = surface_calibrated;
              r.distance = distance;
              r.classifier = classifier;
              return r;
            }),
            py::kw_only (), py::arg ("free_below") = dr.free_below, py::arg ("collision_above") = dr.collision_above,
            py::arg ("exhaustive") = dr.exhaustive, py::arg ("per_point") = dr.per_point,
            py::arg ("enable_timings") = dr.enable_timings, py::arg ("traversal") = dr.traversal,
            py::arg ("rho_min") = dr.rho_min, py::arg ("seed") = dr.seed,
            py::arg ("expanded_k_sigma") = dr.expanded_k_sigma, py::arg ("defer_kernel_fits") = dr.defer_kernel_fits,
            py::arg ("max_leaf_fits") = dr.max_leaf_fits, py::arg ("max_surface_pairs") = dr.max_surface_pairs,
            py::arg ("surface") = dr.surface, py::arg ("surface_pooled") = dr.surface_pooled,
            py::arg ("surface_ladder") = dr.surface_ladder,
            py::arg ("surface_calibrated") = dr.surface_calibrated, py::arg ("distance") = dr.distance,
            py::arg ("classifier") = dr.classifier,
            "Every argument defaults to the C++ CollisionRequest default.")
      .def_readwrite ("free_below", &CollisionRequest::free_below)
      .def_readwrite ("collision_above", &CollisionRequest::collision_above)
      .def_readwrite ("exhaustive", &CollisionRequest::exhaustive)
      .def_readwrite ("per_point", &CollisionRequest::per_point)
      .def_readwrite ("enable_timings", &CollisionRequest::enable_timings)
      .def_readwrite ("traversal", &CollisionRequest::traversal)
      .def_readwrite ("rho_min", &CollisionRequest::rho_min)
      .def_readwrite ("seed", &CollisionRequest::seed)
      .def_readwrite ("expanded_k_sigma", &CollisionRequest::expanded_k_sigma)
      .def_readwrite ("defer_kernel_fits", &CollisionRequest::defer_kernel_fits)
      .def_readwrite ("max_leaf_fits", &CollisionRequest::max_leaf_fits,
                      "At most this many leaf pairs tested (fitted, passed over unfitted, or set aside) a query, nearest first; 0 = no cap.")
      .def_readwrite ("max_surface_pairs", &CollisionRequest::max_surface_pairs,
                      "With surface: the surface layer stops before its next query leaf once this many leaf pairs were\n"
                      "tested (both sides); P is then a lower bound (result.budget_exhausted), and the ladder keeps the\n"
                      "separators' contact. 0 = no cap. Without surface, ValueError.")
      .def_readwrite ("surface", &CollisionRequest::surface,
                      "The surface layer (experimental): fill signed_distance; needs both models built with surface=True.")
      .def_readwrite ("surface_pooled", &CollisionRequest::surface_pooled,
                      "With surface: P is the mean of the surface layer's and the separators' (experimental, default False).\n"
                      "Without surface, collide() and validate() raise ValueError naming it.")
      .def_readwrite ("surface_ladder", &CollisionRequest::surface_ladder,
                      "With surface: the separators first; the surface layer where they reached a leaf pair and found\n"
                      "no sure collision, alone in the contact band, pooled with them where they read free\n"
                      "(experimental, default False; excludes surface_pooled). Without surface, ValueError.")
      .def_readwrite ("surface_calibrated", &CollisionRequest::surface_calibrated,
                      "With surface: P in [0.1, 0.9] through the calibration map fitted on the evaluation's "
                      "procedural scenes (rankings and default verdicts kept). Default False: the model's raw P.\n"
                      "Without surface, ValueError.")
      .def_readwrite ("distance", &CollisionRequest::distance,
                      "Beyond the query's reach (no_leaf_tested), signed_distance is the nearest samples' distance,\n"
                      "its std their covariances' along the line between them with 0.29 of each one's spacing\n"
                      "(result.sample_distance). Near contact the surface layer's signed_distance is then an estimate,\n"
                      "never the first deciding point's bound (it visits every pair, as exhaustive); where the ladder's\n"
                      "separators find a sure collision, the surface layer runs for the distance alone. Default False.")
      .def_readwrite ("classifier", &CollisionRequest::classifier,
                      "The separators' leaf-pair classifier (ClassifierParams; a reference: request.classifier.C = 10 sets it).")
      .def ("validate", &CollisionRequest::validate, "Raises ValueError naming the first member out of range.")
      .def ("__eq__", [] (const CollisionRequest& a, const CollisionRequest& b) { return a == b; })
      .def ("__repr__", [] (const CollisionRequest& r) {
        return "CollisionRequest(free_below=" + num (r.free_below) + ", collision_above=" + num (r.collision_above) +
               ", exhaustive=" + (r.exhaustive ? "True" : "False") + ", per_point=" + (r.per_point ? "True" : "False") +
               ", enable_timings=" + (r.enable_timings ? "True" : "False") + ", traversal=TraversalMode." +
               enumName (r.traversal) + ", rho_min=" + num (r.rho_min) + ", seed=" + std::to_string (r.seed) +
               ", expanded_k_sigma=" + num (r.expanded_k_sigma) +
               ", defer_kernel_fits=" + (r.defer_kernel_fits ? "True" : "False") +
               ", max_leaf_fits=" + std::to_string (r.max_leaf_fits) +
               ", max_surface_pairs=" + std::to_string (r.max_surface_pairs) +
               ", surface=" + (r.surface ? "True" : "False") +
               ", surface_pooled=" + (r.surface_pooled ? "True" : "False") +
               ", surface_ladder=" + (r.surface_ladder ? "True" : "False") +
               ", surface_calibrated=" + (r.surface_calibrated ? "True" : "False") +
               ", distance=" + (r.distance ? "True" : "False") + ", classifier=" + classifierRepr (r.classifier) + ")";
      });

  // --- CollisionResult ----------------------------------------------------------------------------
  py::class_<CollisionResult> res (m, "CollisionResult",
      "Outcome of a query; anything not computed is NaN or Unknown. witness_point/normal are in A's frame.\n"
      "probabilities_a/_b (float32, request.per_point) are index-aligned with the clouds the models were built from.");
  py::enum_<CollisionResult::Status> (res, "Status")
      .value ("Ok", CollisionResult::Status::Ok)
      .value ("InvalidInput", CollisionResult::Status::InvalidInput)
      .value ("NumericalFailure", CollisionResult::Status::NumericalFailure);
  res.def (py::init<> (), "An empty result (status InvalidInput, probability NaN), as in C++.")
      .def_readonly ("status", &CollisionResult::status)
      .def_readonly ("message", &CollisionResult::message)
      .def_readonly ("verdict", &CollisionResult::verdict)
      .def_readonly ("probability", &CollisionResult::probability)
      .def_readonly ("answered_by", &CollisionResult::answered_by,
                     "Whose answer probability is (AnsweredBy): Separators also when request.surface is set but a\n"
                     "model was built without CloudModelParams.surface; with request.surface_ladder, the rung reached.")
      .def_readonly ("signed_distance", &CollisionResult::signed_distance,
                     "Signed distance between the two surfaces in data units (the surface layer, METHOD.md 10a):\n"
                     "> 0 the gap, < 0 minus the penetration depth. NaN when not computed: request.surface off, a\n"
                     "model built without CloudModelParams.surface, or the surfaces never came within reach.\n"
                     "When the query stopped early at a collision (lower_bound), the distance at the first point\n"
                     "that decided it, not the deepest (request.exhaustive visits every pair). From a point deep\n"
                     "inside the other object (or one object wholly inside the other): minus that point's distance\n"
                     "to the other's nearest sample, which the penetration is at least.")
      .def_readonly ("signed_distance_std", &CollisionResult::signed_distance_std,
                     "Standard deviation of signed_distance (both clouds' noise, the fitted surfaces' uncertainty,\n"
                     "the discretisation between samples); NaN with it.")
      .def_readonly ("sample_distance", &CollisionResult::sample_distance,
                     "True when signed_distance is the distance between the two clouds' nearest samples\n"
                     "(request.distance, the objects beyond the query's reach); nearest_point_a/_b are then those samples.")
      .def_property_readonly ("nearest_point_a", [] (const CollisionResult& r) { return vec3 (r.nearest_point_a); })
      .def_property_readonly ("nearest_point_b", [] (const CollisionResult& r) { return vec3 (r.nearest_point_b); })
      .def_readonly ("lower_bound", &CollisionResult::lower_bound)
      .def_readonly ("budget_exhausted", &CollisionResult::budget_exhausted,
                     "True when the query stopped at request.max_leaf_fits (or the surface layer at request.max_surface_pairs)\n"
                     "with leaf pairs left: P is a lower bound.")
      .def_readonly ("full_resolution", &CollisionResult::full_resolution,
                     "True when the answer is the unmerged models' (CloudModelParams.keep_full_resolution): the merged\n"
                     "ones read contact at P >= 0.5 and the unmerged ones found a collision.")
      .def_readonly ("no_leaf_tested", &CollisionResult::no_leaf_tested)
      .def_readonly ("unobserved", &CollisionResult::unobserved,
                     "True when the surface layer's answer rests on surface the samples do not show\n"
                     "(docs/SURFACE.md): the deciding point lies over a hole in the other cloud's samples that the\n"
                     "surface bridges (an occlusion shadow), or behind a scanned sheet whose far side was never seen\n"
                     "(a point clear of the scan's surface there, where none reads inside, reads unknown: P 0.5,\n"
                     "at least 0.25 pooled).\n"
                     "P and the verdict then say what the bridged or occupied surface implies; a planner may treat\n"
                     "such a pose as unknown. Always False without request.surface.")
      .def_readonly ("witness_side", &CollisionResult::witness_side,
                     "Which input holds the point attaining P: +1 a (collide's first model), -1 b, 0 none.")
      .def_readonly ("witness_index", &CollisionResult::witness_index,
                     "That point's index in its own input (-1 when none).")
      .def_property_readonly ("witness_point", [] (const CollisionResult& r) { return vec3 (r.witness_point); })
      .def_property_readonly ("witness_normal", [] (const CollisionResult& r) { return vec3 (r.witness_normal); })
      .def_readonly ("points_a", &CollisionResult::points_a)
      .def_readonly ("points_b", &CollisionResult::points_b)
      .def_readonly ("points_skipped_nonfinite", &CollisionResult::points_skipped_nonfinite)
      .def_readonly ("bv_tests", &CollisionResult::bv_tests)
      .def_readonly ("leaf_pairs_tested", &CollisionResult::leaf_pairs_tested,
                     "Leaf pairs tested: fitted, passed over unfitted because their start plane could not raise P, or set aside by it.")
      .def_readonly ("kernel_leaf_pairs", &CollisionResult::kernel_leaf_pairs)
      .def_readonly ("degenerate_leaf_pairs", &CollisionResult::degenerate_leaf_pairs)
      .def_readonly ("classifier_iterations", &CollisionResult::classifier_iterations)
      .def_readonly ("build_ms", &CollisionResult::build_ms)
      .def_readonly ("query_ms", &CollisionResult::query_ms)
      .def_property_readonly ("probabilities_a", [] (const CollisionResult& r) { return floats (r.probabilities_a); })
      .def_property_readonly ("probabilities_b", [] (const CollisionResult& r) { return floats (r.probabilities_b); })
      .def_property_readonly ("ok", &CollisionResult::ok)
      .def ("in_frame",
            [] (const CollisionResult& r, const py::object& pose) {
              const auto a = poseArray (py::module_::import ("numpy").attr ("asarray") (pose).attr ("reshape") (1, 4, 4));
              CollisionResult out = r;
              pcl_probcollision::mapResultPoints (out, poseAt (a.unchecked<3> (), 0, true));
              return out;
            },
            py::arg ("pose"),
            "A copy with witness_point, witness_normal and (with sample_distance) the nearest points mapped by\n"
            "pose ((4, 4) rigid): collide(a, b, T_a_b) answers in a's frame, in_frame(invert_poses(T_a_b)) in b's,\n"
            "with the bits pcd_collision prints.")
      .def ("__repr__", [] (const CollisionResult& r) {
        // Every member but the per-point arrays: a NaN distance or timing (not computed) and a
        // flag that is False are left out, the vectors shown where they mean something.
        const auto flag = [] (bool v) { return std::string (v ? "True" : "False"); };
        const auto vector = [] (const Eigen::Vector3d& v) {
          return "[" + num (v.x ()) + ", " + num (v.y ()) + ", " + num (v.z ()) + "]";
        };
        std::string s = std::string ("CollisionResult(status=") + enumName (r.status) + ", verdict=Verdict." +
                        enumName (r.verdict) + ", probability=" + num (r.probability) +
                        ", answered_by=AnsweredBy." + enumName (r.answered_by);
        if (!std::isnan (r.signed_distance))
          s += ", signed_distance=" + num (r.signed_distance);
        if (!std::isnan (r.signed_distance_std))
          s += ", signed_distance_std=" + num (r.signed_distance_std);
        if (r.sample_distance)  // the nearest samples the distance is between
          s += ", sample_distance=True, nearest_point_a=" + vector (r.nearest_point_a) +
               ", nearest_point_b=" + vector (r.nearest_point_b);
        if (r.unobserved)
          s += ", unobserved=True";
        if (r.budget_exhausted)
          s += ", budget_exhausted=True";
        if (r.full_resolution)
          s += ", full_resolution=True";
        s += ", lower_bound=" + flag (r.lower_bound) + ", no_leaf_tested=" + flag (r.no_leaf_tested) +
             ", witness_side=" + std::to_string (r.witness_side) + ", witness_index=" + std::to_string (r.witness_index);
        if (r.witness_side != 0)  // a witness: where it is, and its normal
          s += ", witness_point=" + vector (r.witness_point) + ", witness_normal=" + vector (r.witness_normal);
        s += ", points_a=" + std::to_string (r.points_a) + ", points_b=" + std::to_string (r.points_b) +
             ", points_skipped_nonfinite=" + std::to_string (r.points_skipped_nonfinite) +
             ", leaf_pairs_tested=" + std::to_string (r.leaf_pairs_tested) +
             ", kernel_leaf_pairs=" + std::to_string (r.kernel_leaf_pairs) +
             ", degenerate_leaf_pairs=" + std::to_string (r.degenerate_leaf_pairs) +
             ", classifier_iterations=" + std::to_string (r.classifier_iterations) +
             ", bv_tests=" + std::to_string (r.bv_tests);
        if (!std::isnan (r.build_ms))  // timings: request.enable_timings
          s += ", build_ms=" + num (r.build_ms);
        if (!std::isnan (r.query_ms))
          s += ", query_ms=" + num (r.query_ms);
        if (!r.message.empty ())
          s += ", message=" + std::string (py::repr (py::str (r.message)));
        return s + ")";
      });

  // --- CloudModel ---------------------------------------------------------------------------------
  py::class_<CloudModel, ModelPtr> (m, "CloudModel",
      "The immutable model of one object known from a point cloud (uncertain points and their hierarchy).\n"
      "Build it with build_model() or load_model(); it never sees the points again, so moved points need a new model.\n"
      "Any number of queries and threads may share it.")
      .def_property_readonly ("size", &CloudModel::size, "Points in the model (finite rows).")
      .def_property_readonly ("source_size", &CloudModel::sourceSize, "Rows of the input (per-point results align with it).")
      .def_property_readonly ("skipped_points", &CloudModel::skippedPoints, "Rows left out as non-finite (NaN / Inf).")
      .def_property_readonly ("keeps_full_resolution", [] (const CloudModel& model) { return model.fullResolution () != nullptr; },
                              "True when samples were merged and the unmerged model is kept beside the merged one\n"
                              "(CloudModelParams.keep_full_resolution): the full-resolution rung of collide().")
      .def_property_readonly ("merged_samples", &CloudModel::mergedSamples,
                              "Finite rows merged into another by noise_resolution (size is the finite rows minus these);\n"
                              "0 when none merged.")
      .def_property_readonly ("neighbour_scatter_ratio", &CloudModel::neighbourScatterRatio,
                              "Median ratio of the middle to the largest spread of each point's k nearest neighbours: about 0.6 on a\n"
                              "surface scan, near 0 where the samples lie along lines (a LiDAR's rings: warning says so).")
      .def_property_readonly ("coincident_samples", &CloudModel::coincidentSamples,
                              "Samples exactly at an earlier sample's position (and normal), modelled once with it; 0 when none.")
      .def_property_readonly ("origin", [] (const CloudModel& c) { return vec3 (c.origin ()); },
                              "Local frame origin (the centroid), in the cloud's frame.")
      .def_property_readonly ("warning", &CloudModel::warning, "The model's warnings about its input (CloudModel::warning: precision, a merge, normals, lines), '' when none.")
      .def_property_readonly ("build_ms", &CloudModel::buildMilliseconds, "Wall time of the build, ms.")
      .def_property_readonly ("bytes", &CloudModel::bytes, "Memory held, bytes.")
      .def_property_readonly ("median_neighbour_spacing", &CloudModel::medianNeighbourSpacing,
                              "median_spacing() of the points, read from the build's own neighbour search (the same number);\n"
                              "NaN when the build did not search the whole cloud (covariances given, merged samples) or cannot tell.")
      .def_property_readonly ("precision_ratio", &CloudModel::precisionRatio)
      .def_property_readonly ("diagonal", &CloudModel::diagonal,
                              "Bounding-box diagonal of the model's points, data units (collide() judges units by it).")
      .def_property_readonly ("params", [] (const CloudModel& c) { return c.params (); },
                              "A copy of the CloudModelParams it was built with (the model is immutable).")
      .def_property_readonly ("has_surface", [] (const CloudModel& c) { return !c.surface ().empty (); },
                              "True when built with CloudModelParams.surface (the surface layer can query it).")
      .def_property_readonly ("surface_orientation",
                              [] (const CloudModel& c) -> py::object {
                                if (c.surface ().empty ())
                                  return py::none ();
                                return py::cast (c.surface ().orientation ());
                              },
                              "The NormalOrientation the surface model used (Auto resolved), None without a surface.")
      .def_property_readonly ("surface_inside_known", surfaceFlag (&SurfaceModel::insideKnown),
                              "Whether the surface model's orientation says where the inside is (given normals, a viewpoint,\n"
                              "or a propagated one checked closed with CloudModelParams.closed_objects); False: two-sided.\n"
                              "None without a surface.")
      .def_property_readonly ("surface_closed_share", surfaceNumber (&SurfaceModel::closedShare),
                              "With closed_objects and a propagated orientation, the share of probed samples in front of\n"
                              "which the surface reads outside (SurfaceModel::closedShare); NaN where not checked.")
      .def_property_readonly ("surface_solid_share", surfaceNumber (&SurfaceModel::solidShare),
                              "With surface_closed_share, the share of the same probes behind which the surface reads inside\n"
                              "(SurfaceModel::solidShare); NaN where not checked.")
      .def_property_readonly ("surface_hidden_from_viewpoint", surfaceNumber (&SurfaceModel::hiddenFromViewpoint),
                              "Where orientation Auto weighed a viewpoint outside the cloud, or given normals all faced the\n"
                              "viewpoint, the share of points hidden from it behind others (above 0.1 it propagated instead;\n"
                              "SurfaceModel::hiddenFromViewpoint); NaN otherwise.")
      .def_property_readonly ("surface_normals_turned_to_viewpoint", surfaceFlag (&SurfaceModel::normalsTurnedToViewpoint),
                              "Whether orientation Auto set the given normals aside: they all face the viewpoint (as PCL's\n"
                              "normal estimation turns them) while more than 0.1 of the points lie behind others from it, so\n"
                              "they are not outward; their sides were propagated\n"
                              "(SurfaceModel::normalsTurnedToViewpoint). None without a surface.")
      .def_property_readonly ("surface_given_normal_spread_ratio", surfaceNumber (&SurfaceModel::givenNormalSpreadRatio),
                              "Where normals were given, the median over probed samples of their neighbours' spread along the\n"
                              "normal over their mean spread across it: about 0 where the normals belong to the points, 2 where\n"
                              "they lie in the surface (SurfaceModel::givenNormalSpreadRatio); NaN otherwise.")
      .def_property_readonly ("surface_normals_off_surface", surfaceFlag (&SurfaceModel::normalsOffSurface),
                              "Whether orientation Auto set the given normals aside: surface_given_normal_spread_ratio above\n"
                              "1.2, most of them lie along the surface, so they were not moved with their points; each point\n"
                              "took its neighbours' plane instead (SurfaceModel::normalsOffSurface). None without a surface.")
      .def_property_readonly ("surface_given_normal_side_disagreement", surfaceNumber (&SurfaceModel::givenNormalSideDisagreement),
                              "Where given normals disagreed with a viewpoint that sees the cloud as one scan, the share of them\n"
                              "whose side disagrees with their part's majority once one side is carried between neighbours:\n"
                              "about 0 for an orientation, 0.5 for random signs (SurfaceModel::givenNormalSideDisagreement);\n"
                              "NaN otherwise.")
      .def_property_readonly ("surface_given_normals_misoriented", surfaceFlag (&SurfaceModel::givenNormalsMisoriented),
                              "Whether the given normals were never oriented: more than a tenth of them face away from a\n"
                              "viewpoint outside the cloud that sees it as one scan, and their sides disagree between\n"
                              "neighbours (surface_given_normal_side_disagreement above 0.1), as Open3D's estimate_normals\n"
                              "leaves them. Orientation Auto then keeps their directions and turns them toward the viewpoint\n"
                              "(SurfaceModel::givenNormalsMisoriented). None without a surface.")
      .def ("__len__", &CloudModel::size)
      .def ("__repr__", [] (const CloudModel& c) {
        return "CloudModel(size=" + std::to_string (c.size ()) + ", skipped_points=" + std::to_string (c.skippedPoints ()) +
               ", origin=[" + num (c.origin ().x ()) + ", " + num (c.origin ().y ()) + ", " + num (c.origin ().z ()) +
               "], build_ms=" + num (c.buildMilliseconds ()) +
               (c.warning ().empty () ? std::string () : ", warning=" + std::string (py::repr (py::str (c.warning ())))) + ")";
      });

  // --- functions ----------------------------------------------------------------------------------
  m.def ("build_model",
         [] (const py::object& points, const py::object& covariances, const py::object& params, const std::string& name,
             const py::object& viewpoint, const py::object& normals, bool any_length_normals, bool warn) {
           // Not on PCL's console, where the library prints it too: the RuntimeWarning says it
           // once (warn), or CloudModel.warning alone (as pcd_collision keeps the console quiet).
           const pcl_probcollision::io::QuietPclConsole quiet;
           const CloudModel::ConstPtr model = buildModel (points, covariances, params, name, viewpoint, normals, any_length_normals);
           return warn ? warnedModel (model) : std::const_pointer_cast<CloudModel> (model);
         },
         py::arg ("points"), py::arg ("covariances") = py::none (), py::arg ("params") = py::none (),
         py::arg ("name") = "cloud", py::arg ("viewpoint") = py::none (), py::arg ("normals") = py::none (),
         py::kw_only (), py::arg ("any_length_normals") = false, py::arg ("warn") = true,
         "Builds the CloudModel of a cloud given as a numpy array.\n\n"
         "points: (N, 3) float32 or float64 (stored as float32, as pcl::PointXYZ; any strides; float64 points farther\n"
         "    from the origin than 16 times their extent about their box's centre, in double, so that a map frame loses\n"
         "    nothing: CloudModel.origin keeps it). Rows with a NaN or Inf\n"
         "    are skipped and counted (CloudModel.skipped_points); ValueError if none is finite or N == 0. An (H, W, 3)\n"
         "    image of points (a depth camera's, NaN where a pixel has none) is an organized cloud: where its\n"
         "    VIEWPOINT is not the sensor its rows and columns meet at (organized_sensor_pose), the model takes that\n"
         "    sensor's pose, with a RuntimeWarning. Its covariances and normals are then (H, W, 3, 3) and (H, W, 3),\n"
         "    or flattened in row order.\n"
         "covariances: optional (N, 3, 3) float32/float64, symmetric; estimated from the k nearest neighbours when None.\n"
         "    Given, they are the whole spread: params.noise is not added. A row with a NaN drops its point.\n"
         "params: CloudModelParams (None = CloudModelParams()).\n"
         "name: what error messages call the cloud.\n"
         "viewpoint: optional sensor pose tx ty tz qw qx qy qz (a PCD's VIEWPOINT; None = the origin, looking along +z).\n"
         "normals: optional (N, 3) float32/float64 outward unit normals (a mesh's: sample_mesh_with_normals), used by\n"
         "    the surface model (params.surface) under the Auto and PointNormals orientations; a row with NaN or 0 has\n"
         "    none. The points' model is the same with or without them (pcl::PointNormal instead of pcl::PointXYZ).\n"
         "any_length_normals: keyword only; True takes the normals of any length, as a file stores them (read_cloud_with_normals)\n"
         "    and as pcd_collision -surface reads them: the surface model normalizes them. False: not unit length is a ValueError.\n"
         "A RuntimeWarning carries CloudModel.warning when the points, held in float, lost precision far from the origin,\n"
         "    or given normals do not belong to them; warn=False (keyword only) leaves it in CloudModel.warning alone (for\n"
         "    a caller that reports it itself, as pcl_probcollision.dask does). PCL's console stays quiet during the build.\n"
         "Releases the GIL while building.");
  m.def ("organized_sensor_pose",
         [] (const py::object& points) -> py::object {
           const pcl::PointCloud<pcl::PointXYZ> cloud = cloudOf (points, "points", true);
           std::optional<SensorPose> pose;
           {
             py::gil_scoped_release release;
             pose = organizedSensorPose (cloud);
           }
           if (!pose)
             return py::none ();
           return py::make_tuple (py::array_t<double> (3, pose->origin.data ()), py::array_t<double> (3, pose->axis.data ()));
         },
         py::arg ("points"),
         "Where the pinhole sensor (a depth camera, a rectified stereo pair) that captured an organized cloud was:\n"
         "    (origin, axis), two float64 arrays of 3 (the optical centre and the unit optical axis, toward the\n"
         "    points), or None where its rows and columns do not say it (a lidar's rings, an image of one plane\n"
         "    without noise, fewer than 3 rows or columns that span a plane).\n"
         "points: (H, W, 3) float32/float64, the image's points, NaN where a pixel has none. The planes of its rows\n"
         "    and of its columns meet at the optical centre, so the pose moves with the points: after a rigid\n"
         "    transform it is where the sensor now is. As build_model(viewpoint=) takes a pose: (*origin, 1, 0, 0, 0)\n"
         "    places it (the axis matters only to the depth noise models). build_model (given an (H, W, 3) image),\n"
         "    load_model and pcd_collision do this themselves for an organized cloud whose VIEWPOINT lies elsewhere\n"
         "    (with a warning).");
  m.def ("load_model",
         [] (const std::filesystem::path& path, const py::object& params, const py::object& name) {
           // The file's rounding to float, when it matters, says more than the model's own
           // precision warning (which then is not repeated), as pcd_collision's warnings do.
           std::string file_warning;
           const pcl_probcollision::io::QuietPclConsole quiet;  // the RuntimeWarning says it once
           const CloudModel::ConstPtr model = loadModel (path, params, name, file_warning);
           if (file_warning.empty ())
             return warnedModel (model);
           if (PyErr_WarnEx (PyExc_RuntimeWarning, utf8Text (file_warning).c_str (), 1) < 0)
             throw py::error_already_set ();
           return std::const_pointer_cast<CloudModel> (model);
         },
         py::arg ("path"), py::arg ("params") = py::none (), py::arg ("name") = py::none (),
         "Builds the CloudModel of a .pcd file (x y z fields, any numeric type; its VIEWPOINT is the sensor pose) or of a\n"
         "    .ply declaring no face (its camera element, if any, is the sensor pose), as pcd_collision reads them.\n\n"
         "params: CloudModelParams (None = defaults); name: defaults to the file name.\n"
         "With params.surface, a file with normal_x normal_y normal_z fields (any numeric type) gives its points\n"
         "    those normals, as build_model(normals=) does: taken as outward by the Auto and PointNormals\n"
         "    orientations (surface_orientation is then PointNormals); any length is accepted (the surface model\n"
         "    normalizes them), and a point whose normal is NaN or 0 is oriented from its neighbours. Without\n"
         "    params.surface the normals are not read (they change nothing else in the model).\n"
         "FileNotFoundError for a missing file, IsADirectoryError for a directory, ValueError for a file PCL cannot\n"
         "    read or one with only some of the\n"
         "    normal fields (with params.surface). A RuntimeWarning says when the file stores x y z in double precision\n"
         "    so far from the origin that their rounding to float passes a tenth of an isotropic sigma (under another\n"
         "    noise model, 1e-5 of the cloud's size), as pcd_collision warns; otherwise it carries CloudModel.warning,\n"
         "    as build_model's.");
  m.attr ("__version__") = std::string (libraryVersion ());  // project(VERSION), as pcd_collision -version
  m.attr ("MAX_COORDINATE") = detail::kMaxCoordinate;  // the library's coordinate and translation bound
  m.attr ("MAX_THREADS") = detail::kMaxThreads;         // the library's cap on a thread count
  // pcd_collision's own defaults (pcd_collision::Defaults), which the Dask command line shares.
  m.attr ("PCD_COLLISION_SENSOR") = std::string (pcd_collision::Defaults::sensor);
  m.attr ("PCD_COLLISION_SIGMA") = pcd_collision::Defaults::sigma;
  m.attr ("PCD_COLLISION_MESH_SEED") = pcd_collision::Defaults::mesh_sampling_seed;
  // .none (false): None is not a model (pybind11 would pass a null pointer; found in review).
  m.def ("collide", &collideOne, py::arg ("a").none (false), py::arg ("b").none (false), py::arg ("pose"),
         py::arg ("request") = py::none (), py::kw_only (), py::arg ("check_units") = true,
         "Probability that the objects of models a and b collide, b placed in a's frame by pose = T_a_b\n"
         "(a 4x4 rigid transform, or a pair (R, t)), exactly as the C++ collide(). A rotation rounded to a few\n"
         "digits (R^T R within 1e-2 of the identity: a quaternion printed with 3 decimals) is taken to its\n"
         "nearest rotation.\n\n"
         "request: CollisionRequest (None = CollisionRequest()). Returns a CollisionResult.\n"
         "ValueError (with the C++ message) for a non-rigid or non-finite pose or an invalid request.\n"
         "check_units: a RuntimeWarning, pcd_collision's, when the models' sizes (CloudModel.diagonal) differ by over\n"
         "    100x: most likely one is in millimetres and the other in metres (the answer is for the numbers given).");
  m.def ("collide_batch", &collideMany, py::arg ("a").none (false), py::arg ("b").none (false), py::arg ("poses"),
         py::arg ("request") = py::none (), py::arg ("threads") = 0, py::kw_only (), py::arg ("check_units") = true,
         "collide() for each pose of an (M, 4, 4) array, on `threads` threads (0 = all cores), GIL released.\n\n"
         "Returns a list of M CollisionResult in pose order, each equal to collide(a, b, poses[i], request)\n"
         "(timings aside). ValueError naming the first invalid pose, or naming threads outside [0, MAX_THREADS]\n"
         "(as pcd_collision refuses -threads). check_units as collide()'s.");
  m.def ("verdict_for", &verdictFor, py::arg ("probability"), py::arg ("request"),
         "The verdict of a probability under a request's thresholds (Unknown for NaN). ValueError naming\n"
         "free_below or collision_above when out of range (free_below in (0, 0.5], collision_above in [0.5, 1)),\n"
         "or the probability when it is outside [0, 1].");

  // --- file input and poses as pcd_collision reads them (io/, used by pcl_probcollision.dask) ------
  m.def ("read_cloud", &readCloud, py::arg ("path"), py::kw_only (), py::arg ("rounding") = false,
         "Reads a .pcd (or face-less .ply) file as pcd_collision does.\n\n"
         "Returns (points (N, 3) float32 with NaN rows kept, viewpoint (7,) tx ty tz qw qx qy qz, width, height).\n"
         "rounding=True appends what holding x y z in float cost: (largest change of a coordinate, largest |coordinate|),\n"
         "    (0, 0) for a file that stores them as float32 (InputFacts.rounding, rounding_warning()).\n"
         "ValueError with pcd_collision's message for a file it cannot read.");
  m.def ("read_cloud_with_normals", &readCloudWithNormals, py::arg ("path"), py::kw_only (), py::arg ("rounding") = false,
         "read_cloud with the file's normal_x normal_y normal_z, as pcd_collision -surface reads them.\n\n"
         "Returns (points (N, 3) float32, normals (N, 3) float32 as stored (any length; NaN rows: none) or None when the\n"
         "file has no normal fields, viewpoint (7,), width, height); rounding=True appends the rounding as read_cloud's.\n"
         "ValueError with pcd_collision's message for a file it cannot read, or with only some of the three normal fields.");
  // The command lines' warnings about their inputs (io/input_warnings.h), which the Dask command
  // line prints as pcd_collision does.
  py::class_<pcl_probcollision::io::InputFacts> (m, "InputFacts",
                                                 "What the command lines' input warnings judge of one input, as read.")
      .def (py::init ([] (const std::string& path, bool cloud, std::size_t finite, double diagonal,
                          std::pair<double, double> rounding, const std::string& sensor, double sigma) {
              pcl_probcollision::io::InputFacts f;
              f.path = path;
              f.cloud = cloud;
              f.finite = finite;
              f.diagonal = diagonal;
              f.rounding.largest_change = rounding.first;
              f.rounding.largest_magnitude = rounding.second;
              f.sensor = sensor;
              f.sigma = sigma;
              return f;
            }),
            py::kw_only (), py::arg ("path"), py::arg ("cloud") = true, py::arg ("finite") = 0, py::arg ("diagonal") = 0.0,
            py::arg ("rounding") = std::pair<double, double> (0.0, 0.0), py::arg ("sensor") = "isotropic",
            py::arg ("sigma") = 0.0,
            "path as given; cloud False for a mesh; finite points; diagonal of the finite points' (a mesh's vertices')\n"
            "bounding box; rounding as read_cloud(rounding=True) returns it; sensor a noise model's name; sigma the\n"
            "isotropic sigma (data units).")
      .def_readonly ("path", &pcl_probcollision::io::InputFacts::path)
      .def_readonly ("cloud", &pcl_probcollision::io::InputFacts::cloud)
      .def_readonly ("finite", &pcl_probcollision::io::InputFacts::finite)
      .def_readonly ("diagonal", &pcl_probcollision::io::InputFacts::diagonal)
      .def_readonly ("sensor", &pcl_probcollision::io::InputFacts::sensor)
      .def_readonly ("sigma", &pcl_probcollision::io::InputFacts::sigma);
  m.def ("finite_diagonal",
         [] (const py::object& points) { return pcl_probcollision::io::finiteDiagonal (cloudOf (points, "points")); },
         py::arg ("points"),
         "Bounding-box diagonal of the finite rows of (N, 3) points held as float32, as pcd_collision measures a cloud\n"
         "for its warnings (InputFacts.diagonal); 0 for none or one.");
  m.def ("scale_warning", &pcl_probcollision::io::scaleWarning, py::arg ("a"), py::arg ("b"),
         "pcd_collision's warning when the inputs' sizes differ by more than 100x (units); '' when none.");
  m.def ("noise_warning", &pcl_probcollision::io::noiseWarning, py::arg ("input"),
         "pcd_collision's warning when a cloud's isotropic sigma is under 1e-5 of its size (units); '' when none.");
  m.def ("rounding_warning", &pcl_probcollision::io::roundingWarning, py::arg ("input"),
         "pcd_collision's warning when holding a file's x y z in float moved one by more than a tenth of its isotropic\n"
         "sigma (under another model, 1e-5 of its size); '' when none.");
  m.def ("model_warning", &pcl_probcollision::io::modelWarning, py::arg ("input"), py::arg ("model_warning"),
         "A model's precision warning (CloudModel.warning) naming its file, '' when it has none or when\n"
         "rounding_warning(input) already said it.");
  m.def ("between_samples_warning", &pcl_probcollision::io::betweenSamplesWarning, py::arg ("both_meshes"),
         py::arg ("free"), py::arg ("leaf_pairs_tested"), py::arg ("where"), py::arg ("spacing"),
         "pcd_collision's warning for a free answer between two meshes' samples (where: 'pose 3'); '' when none.");
  m.def ("coarse_mesh_warning", &pcl_probcollision::io::coarseMeshWarning, py::arg ("free"), py::arg ("leaf_pairs_tested"),
         py::arg ("where"), py::arg ("mesh_path"), py::arg ("mesh_spacing"), py::arg ("cloud_spacing"),
         "pcd_collision's warning for a free answer within reach between a mesh sampled mesh_spacing apart (its\n"
         "-mesh_density) and a cloud more than twice finer (median spacing cloud_spacing); '' when none.");
  m.def ("is_faceless_ply",
         [] (const std::filesystem::path& p) {
           requireRegularFile (p);
           return pcl_probcollision::io::isFacelessPly (p.string ());
         },
         py::arg ("path"),
         "True for a .ply whose header declares no face (pcd_collision reads it as a cloud). FileNotFoundError or\n"
         "IsADirectoryError for a path that is no file.");
  m.def ("read_mesh",
         [] (const std::filesystem::path& path) {
           requireRegularFile (path);
           pcl_probcollision::io::TriangleMesh mesh;
           std::string error;
           if (!pcl_probcollision::io::loadTriangleMesh (path.string (), mesh, error))
             throw py::value_error ("path: " + error);
           py::array_t<double> V ({static_cast<py::ssize_t> (mesh.vertices.size ()), static_cast<py::ssize_t> (3)});
           py::array_t<int> F ({static_cast<py::ssize_t> (mesh.triangles.size ()), static_cast<py::ssize_t> (3)});
           auto v = V.mutable_unchecked<2> ();
           auto f = F.mutable_unchecked<2> ();
           for (std::size_t i = 0; i < mesh.vertices.size (); ++i)
             for (int d = 0; d < 3; ++d)
               v (static_cast<py::ssize_t> (i), d) = mesh.vertices[i][static_cast<std::size_t> (d)];
           for (std::size_t i = 0; i < mesh.triangles.size (); ++i)
             for (int d = 0; d < 3; ++d)
               f (static_cast<py::ssize_t> (i), d) = mesh.triangles[i][static_cast<std::size_t> (d)];
           return py::make_tuple (V, F);
         },
         py::arg ("path"),
         "A triangle mesh (.ply .obj .stl .vtk) as pcd_collision reads it: (vertices (V, 3), triangles (T, 3)).\n"
         "FileNotFoundError or IsADirectoryError for a path that is no file; ValueError for a file that is no mesh.");
  m.def ("sample_mesh",
         [] (const py::object& vertices, const py::object& triangles, double spacing, std::uint64_t seed) {
           const auto mesh = meshOf (vertices, triangles);
           pcl::PointCloud<pcl::PointXYZ> cloud;
           try
           {
             py::gil_scoped_release release;
             cloud = pcl_probcollision::io::sampleMesh (mesh, spacing, seed);
           }
           catch (const std::runtime_error& e)  // the sampler's spacing checks: a ValueError here
           {
             throw py::value_error (spacingError (e));
           }
           return cloudArray (cloud);
         },
         py::arg ("vertices"), py::arg ("triangles"), py::arg ("spacing"), py::arg ("seed") = 20111,
         "pcd_collision's MeshSampled-mode samples (vertices first, then area samples at `spacing`), float32 (N, 3).");
  m.def ("sample_mesh_with_normals",
         [] (const py::object& vertices, const py::object& triangles, double spacing, std::uint64_t seed) {
           const auto mesh = meshOf (vertices, triangles);
           pcl::PointCloud<pcl::PointNormal> cloud;
           try
           {
             py::gil_scoped_release release;
             cloud = pcl_probcollision::io::sampleMeshWithNormals (mesh, spacing, seed);
           }
           catch (const std::runtime_error& e)  // the sampler's spacing checks: a ValueError here
           {
             throw py::value_error (spacingError (e));
           }
           py::array_t<float> points ({static_cast<py::ssize_t> (cloud.size ()), static_cast<py::ssize_t> (3)});
           py::array_t<float> normals ({static_cast<py::ssize_t> (cloud.size ()), static_cast<py::ssize_t> (3)});
           auto p = points.mutable_unchecked<2> ();
           auto n = normals.mutable_unchecked<2> ();
           for (std::size_t i = 0; i < cloud.size (); ++i)
             for (int d = 0; d < 3; ++d)
             {
               p (static_cast<py::ssize_t> (i), d) = cloud[i].data[d];
               n (static_cast<py::ssize_t> (i), d) = cloud[i].data_n[d];
             }
           return py::make_tuple (points, normals);
         },
         py::arg ("vertices"), py::arg ("triangles"), py::arg ("spacing"), py::arg ("seed") = 20111,
         "sample_mesh()'s points (the same ones) with outward unit normals, float32 (N, 3) each: a sample's is its\n"
         "triangle's, a vertex's the area-weighted mean of its triangles' (faces wound counter-clockwise seen from\n"
         "outside). pcd_collision's mesh input with -surface: build_model(points, zeros, params, normals=normals).");
  m.def ("mesh_pair_spacing",
         [] (const py::object& vertices_a, const py::object& triangles_a, const py::object& vertices_b,
             const py::object& triangles_b) {
           return pcl_probcollision::io::meshPairSpacing (meshOf (vertices_a, triangles_a), meshOf (vertices_b, triangles_b));
         },
         py::arg ("vertices_a"), py::arg ("triangles_a"), py::arg ("vertices_b"), py::arg ("triangles_b"),
         "pcd_collision's sample spacing when both inputs are meshes: 1/100 of the smaller bounding-box diagonal,\n"
         "or wider so that both together expect 500,000 samples.");
  m.def ("is_closed_mesh",
         [] (const py::object& vertices, const py::object& triangles) {
           return pcl_probcollision::io::isClosedMesh (meshOf (vertices, triangles));
         },
         py::arg ("vertices"), py::arg ("triangles"),
         "Whether the mesh bounds a solid, as pcd_collision judges it: with vertices at one position taken as one,\n"
         "every edge of a triangle with an area borders two triangles wound oppositely. Given as normals, an open\n"
         "mesh's face normals still enclose an inside (a box resting in a bin reads inside the bin); build an open\n"
         "container's samples without normals (orientation=NormalOrientation.Propagate: two-sided) instead.");
  m.def ("mesh_signed_volume",
         [] (const py::object& vertices, const py::object& triangles) {
           return pcl_probcollision::io::meshSignedVolume (meshOf (vertices, triangles));
         },
         py::arg ("vertices"), py::arg ("triangles"),
         "The volume a closed mesh's faces enclose by their winding: positive wound outward, negative wound inward\n"
         "(a cavity, or a solid exported inside out).");
  m.def ("open_mesh_warning",
         [] (const std::string& path, const py::object& vertices, const py::object& triangles,
             const std::string& orientation_option) {
           return pcl_probcollision::io::openMeshWarning (path, pcl_probcollision::io::meshEdges (meshOf (vertices, triangles)),
                                                          orientation_option);
         },
         py::arg ("path"), py::arg ("vertices"), py::arg ("triangles"), py::arg ("orientation_option"),
         "pcd_collision's warning for a mesh oriented by its faces under -surface that is not closed (open, or with\n"
         "faces wound against their neighbours), naming the option that orients it otherwise; '' for a closed mesh.");
  m.def ("inside_out_mesh_warning", &pcl_probcollision::io::insideOutMeshWarning, py::arg ("path"), py::arg ("closed"),
         py::arg ("signed_volume"), py::arg ("orientation_option"), py::arg ("closed_option"),
         "pcd_collision's warning for a closed mesh oriented by its faces under -surface whose faces wind inward\n"
         "(signed_volume: mesh_signed_volume < 0), naming the options that orient it outward; '' otherwise.");
  m.def ("mesh_diagonal",
         [] (const py::object& vertices, const py::object& triangles) {
           return pcl_probcollision::io::meshDiagonal (meshOf (vertices, triangles));
         },
         py::arg ("vertices"), py::arg ("triangles"), "Bounding-box diagonal of a mesh, as pcd_collision measures it.");
  m.def ("median_spacing",
         [] (const py::object& points) {
           const pcl::PointCloud<pcl::PointXYZ> cloud = cloudOf (points, "points");
           py::gil_scoped_release release;
           return pcl_probcollision::io::medianSpacing (cloud);
         },
         py::arg ("points"), "Median nearest-neighbour spacing of a cloud (pcd_collision's mesh sample spacing).");
  m.def ("pcd_collision_usage_error",
         [] (const std::vector<std::string>& args) {
           const pcd_collision::ParseResult r = pcd_collision::parseCommandLine (args);
           return r.kind == pcd_collision::ParseResult::Kind::Error ? r.error : std::string ();
         },
         py::arg ("args"),
         "pcd_collision's usage error for these arguments (its argv without the program's name), in its words;\n"
         "empty when its parser accepts them. The Dask command line judges pcd_collision's flags with it.");
  m.def ("pcd_collision_input_usage_error",
         [] (const std::vector<std::string>& flags, bool mesh_a, bool mesh_b, const std::string& name_a,
             const std::string& name_b) {
           pcd_collision::Options o = optionsOfFlags (flags);
           o.input_a = name_a;
           o.input_b = name_b;
           return pcd_collision::inputKindsUsageError (o, mesh_a, mesh_b);
         },
         py::arg ("flags"), py::arg ("mesh_a"), py::arg ("mesh_b"), py::arg ("name_a") = "a.pcd", py::arg ("name_b") = "b.pcd",
         "pcd_collision's usage error for flags that need an input of a kind the inputs are not (its\n"
         "inputKindsUsageError: -mesh_density with two clouds, -sigma_a or -sensor_a for a mesh), once their\n"
         "kinds are known (mesh_a, mesh_b: whether <a>, <b> is a mesh; name_a, name_b: how the message names\n"
         "them); empty when there is none. ValueError with its usage error for flags its parser refuses.");
  m.def ("pcd_collision_params",
         [] (const std::vector<std::string>& flags) {
           const pcd_collision::Options o = optionsOfFlags (flags);
           return py::make_tuple (pcd_collision::modelParamsFor (o, true), pcd_collision::modelParamsFor (o, false),
                                  pcd_collision::requestFor (o));
         },
         py::arg ("flags"),
         "What pcd_collision makes of its flags (without the inputs): (CloudModelParams of <a>, of <b>, CollisionRequest),\n"
         "by its own modelParamsFor and requestFor; the noise is left unset (the caller's, per input). ValueError with\n"
         "its usage error.");
  m.def ("pcd_collision_json_lines", &pcdCollisionJsonLines, py::arg ("flags"), py::arg ("input_a"),
         py::arg ("input_b"), py::arg ("fields"), py::arg ("poses"), py::arg ("build_ms"),
         "pcd_collision's -json lines (its own writer, docs/CLI.md) for answers held as columns.\n\n"
         "flags: pcd_collision's flags (without the inputs and -poses); input_a/_b: dicts with path, kind ('cloud' or\n"
         "'mesh'), points (count), finite, width, height (clouds), vertices, triangles, spacing, spacing_source\n"
         "(meshes), load_ms, sample_ms, merged_samples (None: null) and surface (None, or a dict of orientation,\n"
         "inside_known, hidden_from_viewpoint, closed_share, solid_share); fields: one array per CollisionResult\n"
         "member, a row a pose, the witness and nearest points in b's frame; poses: (M, 6) as in the -poses file;\n"
         "build_ms: the models' build, reported on the first pose. Returns M strings without newlines.");
  m.def ("read_poses", &readPoses, py::arg ("path"),
         "Reads pcd_collision's -poses file: six numbers a line (tx ty tz roll pitch yaw) separated by blanks\n"
         "and/or one comma, '#' comments and blank lines allowed.\n\n"
         "Returns (M, 6) float64. FileNotFoundError or IsADirectoryError for a path that is no file; ValueError with\n"
         "pcd_collision's message (\"path: FILE:LINE: reason\") for a malformed line or a file without a pose.");
  m.def ("parse_poses", &parsePoses, py::arg ("text"), py::arg ("name") = "standard input",
         "Reads the bytes of a -poses file (pcd_collision -poses - reads them from standard input) as read_poses\n"
         "reads the file. Returns (M, 6) float64; ValueError with pcd_collision's message (\"text: NAME:LINE: reason\").");
  m.def ("poses_from_xyzrpy", &posesFromXyzRpy, py::arg ("poses"),
         "(M, 6) tx ty tz roll pitch yaw -> (M, 4, 4), R = Rz(yaw) Ry(pitch) Rx(roll), as pcd_collision's -pose.\n\n"
         "Such a pose moves <a> into <b>'s frame (T_b_a); collide(a, b, T) and collide_batch take T_a_b, so pass\n"
         "invert_poses() of these to answer as pcd_collision does.");
  m.def ("check_poses",
         [] (const py::object& obj) {
           const auto a = poseArray (obj);
           const auto p = a.unchecked<3> ();
           for (py::ssize_t k = 0; k < p.shape (0); ++k)
             poseAt (p, k, true);
         },
         py::arg ("poses"),
         "ValueError naming the first of (M, 4, 4) poses that collide() would refuse (not finite, not rigid within\n"
         "its tolerance, beyond MAX_COORDINATE) or whose last row is not 0 0 0 1; None when all are good.");
  m.def ("invert_poses", &invertPoses, py::arg ("poses"),
         "(M, 4, 4) rigid transforms -> their inverses (Eigen's), of the nearest rotation where one was rounded,\n"
         "as collide() takes it. ValueError naming the first that is not rigid (the rotation's tolerance is\n"
         "collide()'s) or whose last row is not 0 0 0 1.");
}
