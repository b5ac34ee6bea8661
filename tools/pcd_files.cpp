// SPDX-License-Identifier: BSD-3-Clause
#include "pcd_files.h"

#include <pcl_probcollision/collision.h>

#include <pcl/PCLPointCloud2.h>
#include <pcl/common/io.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace pcd_collision
{
namespace
{
// The temporary file of writeResultCloud while it exists, for the signal handler: an interrupted
// run (SIGINT, SIGTERM, SIGHUP) must leave no partial file behind (docs/RELIABILITY.md).
char g_temp_path[4096];
volatile sig_atomic_t g_temp_active = 0;

/** \brief The file that writing `path` should replace: the end of its chain of symbolic links
  * (a dangling link's target), else `path`. The atomic rename would otherwise replace the link
  * itself, where a shell's `>` writes through it. False, naming `path`, on a loop of links. */
bool
followLinks (const std::string& path, std::filesystem::path& target, std::string& error)
{
  namespace fs = std::filesystem;
  constexpr int kMaxLinks = 40; // Linux's own limit (ELOOP)
  target = path;
  std::error_code ec;
  for (int hops = 0; fs::is_symlink (fs::symlink_status (target, ec)); ++hops)
  {
    const fs::path next = fs::read_symlink (target, ec);
    if (ec || hops == kMaxLinks)
    {
      error = "cannot write '" + path + "': " + (ec ? ec.message () : std::strerror (ELOOP));
      return false;
    }
    target = next.is_absolute () ? next : target.parent_path () / next;
  }
  return true;
}

extern "C" void
removeTempAndDie (int sig)
{
  // Only async-signal-safe calls: unlink, sigaction, raise.
  if (g_temp_active)
    ::unlink (g_temp_path);
  struct sigaction dfl;
  std::memset (&dfl, 0, sizeof (dfl));
  dfl.sa_handler = SIG_DFL;
  ::sigaction (sig, &dfl, nullptr);
  ::raise (sig);  // die of the same signal, so the parent sees it
}

/** \brief Blocks the interrupting signals for its lifetime, so that creating the temporary file
  * and registering it for removal happen as one step. */
class BlockInterrupts
{
public:
  BlockInterrupts ()
  {
    sigset_t set;
    sigemptyset (&set);
    sigaddset (&set, SIGINT);
    sigaddset (&set, SIGTERM);
    sigaddset (&set, SIGHUP);
    ::sigprocmask (SIG_BLOCK, &set, &old_);
  }
  ~BlockInterrupts () { ::sigprocmask (SIG_SETMASK, &old_, nullptr); }
  BlockInterrupts (const BlockInterrupts&) = delete;
  BlockInterrupts& operator= (const BlockInterrupts&) = delete;

private:
  sigset_t old_;
};

void
setTempPath (const char* path)
{
  BlockInterrupts block;
  if (!path)
  {
    g_temp_active = 0;
    return;
  }
  std::strncpy (g_temp_path, path, sizeof (g_temp_path) - 1);
  g_temp_path[sizeof (g_temp_path) - 1] = '\0';
  g_temp_active = 1;
}

} // namespace

void
installInterruptCleanup ()
{
  struct sigaction sa;
  std::memset (&sa, 0, sizeof (sa));
  sa.sa_handler = removeTempAndDie;
  sigemptyset (&sa.sa_mask);
  for (const int sig : {SIGINT, SIGTERM, SIGHUP})
  {
    struct sigaction old;
    // Keep "ignored" (e.g. nohup) as it was.
    if (::sigaction (sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN)
      continue;
    ::sigaction (sig, &sa, nullptr);
  }
}

std::uint32_t
verdictColour (pcl_probcollision::Verdict verdict)
{
  switch (verdict)
  {
    case pcl_probcollision::Verdict::Free: return 0x00c000u;         // green
    case pcl_probcollision::Verdict::InContact: return 0xffff00u;    // yellow
    case pcl_probcollision::Verdict::InCollision: return 0xff0000u;  // red
    case pcl_probcollision::Verdict::Unknown: break;
  }
  return 0x808080u;  // not evaluated: grey
}

bool
writeResultCloud (const std::string& path, const std::vector<LabelledCloud>& sides,
                  const pcl_probcollision::CollisionRequest& request, const Eigen::Vector4f& origin, const Eigen::Quaternionf& orientation,
                  std::size_t& points_written, std::string& error)
{
  pcl::PCLPointCloud2 blob;
  auto field = [&] (const char* name, std::uint32_t offset, std::uint8_t type) {
    pcl::PCLPointField f;
    f.name = name;
    f.offset = offset;
    f.datatype = type;
    f.count = 1;
    blob.fields.push_back (f);
  };
  field ("x", 0, pcl::PCLPointField::FLOAT32);
  field ("y", 4, pcl::PCLPointField::FLOAT32);
  field ("z", 8, pcl::PCLPointField::FLOAT32);
  field ("intensity", 12, pcl::PCLPointField::FLOAT32);
  field ("rgb", 16, pcl::PCLPointField::FLOAT32);  // PCL's packed-colour convention
  field ("label", 20, pcl::PCLPointField::UINT32);
  blob.point_step = 24;
  std::size_t n = 0;
  for (const auto& s : sides)
    n += s.cloud->size ();
  blob.width = static_cast<std::uint32_t> (n);
  blob.height = 1;
  blob.row_step = blob.point_step * blob.width;
  blob.is_bigendian = false;
  blob.data.resize (n * blob.point_step);
  bool dense = true;
  std::uint8_t* out = blob.data.data ();
  for (const auto& s : sides)
  {
    for (std::size_t i = 0; i < s.cloud->size (); ++i, out += blob.point_step)
    {
      const auto& p = (*s.cloud)[i];
      const float prob = (s.probabilities && i < s.probabilities->size ()) ? (*s.probabilities)[i]
                                                                           : std::numeric_limits<float>::quiet_NaN ();
      const std::uint32_t rgb = verdictColour (pcl_probcollision::verdictFor (prob, request));
      std::memcpy (out + 0, &p.x, 4);
      std::memcpy (out + 4, &p.y, 4);
      std::memcpy (out + 8, &p.z, 4);
      std::memcpy (out + 12, &prob, 4);
      std::memcpy (out + 16, &rgb, 4);
      std::memcpy (out + 20, &s.label, 4);
      dense = dense && std::isfinite (p.x) && std::isfinite (p.y) && std::isfinite (p.z);
    }
  }
  blob.is_dense = dense;

  namespace fs = std::filesystem;
  fs::path target;
  if (!followLinks (path, target, error))
    return false;
  const fs::path dir = target.has_parent_path () ? target.parent_path () : fs::path (".");
  std::string tmpl = (dir / ("." + target.filename ().string () + ".tmp-XXXXXX")).string ();
  std::vector<char> buf (tmpl.begin (), tmpl.end ());
  buf.push_back ('\0');
  if (buf.size () >= sizeof (g_temp_path))
  {
    error = "cannot write '" + path + "': path too long";
    return false;
  }
  int fd = -1;
  {
    // Create and register together: a signal in between would leave the file behind.
    BlockInterrupts block;
    fd = ::mkstemp (buf.data ());
    if (fd >= 0)
      setTempPath (buf.data ());
  }
  if (fd < 0)
  {
    error = "cannot write '" + path + "': " + std::strerror (errno);
    return false;
  }
  // mkstemp creates 0600; give the result the usual 0666 & ~umask.
  const mode_t mask = ::umask (0);
  ::umask (mask);
  ::fchmod (fd, 0666 & ~mask);
  ::close (fd);
  const std::string tmp (buf.data ());

  int rc = -1;
  try
  {
    pcl::PCDWriter writer;
    rc = writer.writeBinary (tmp, blob, origin, orientation);
  }
  catch (const std::exception&)
  {
    rc = -1;
  }
  if (rc != 0)
  {
    std::remove (tmp.c_str ());
    setTempPath (nullptr);
    error = "cannot write '" + path + "' (writing the PCD data failed)";
    return false;
  }
  int renamed = -1, e = 0;
  {
    // Rename and unregister as one step: afterwards the temporary name must not be removed.
    BlockInterrupts block;
    renamed = std::rename (tmp.c_str (), target.c_str ());
    e = errno;
    if (renamed == 0)
      setTempPath (nullptr);
  }
  if (renamed != 0)
  {
    std::remove (tmp.c_str ());
    setTempPath (nullptr);
    error = "cannot write '" + path + "': " + std::strerror (e);
    return false;
  }
  points_written = n;
  return true;
}
} // namespace pcd_collision
