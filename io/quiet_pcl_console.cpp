// SPDX-License-Identifier: BSD-3-Clause
#include "quiet_pcl_console.h"

#include <mutex>

namespace pcl_probcollision::io
{
namespace
{
// The shared silence: how many instances are alive, and the level before the first.
std::mutex g_mutex;
int g_depth = 0;
pcl::console::VERBOSITY_LEVEL g_level_before = pcl::console::L_INFO;
} // namespace

QuietPclConsole::QuietPclConsole () : quiet_ (!readerMessagesShown ())
{
  if (!quiet_)
    return;
  const std::lock_guard<std::mutex> lock (g_mutex);
  if (g_depth++ == 0)
  {
    g_level_before = pcl::console::getVerbosityLevel ();
    pcl::console::setVerbosityLevel (pcl::console::L_ALWAYS);
  }
}

QuietPclConsole::~QuietPclConsole ()
{
  if (!quiet_)
    return;
  const std::lock_guard<std::mutex> lock (g_mutex);
  if (--g_depth == 0)
    pcl::console::setVerbosityLevel (g_level_before);
}
} // namespace pcl_probcollision::io
