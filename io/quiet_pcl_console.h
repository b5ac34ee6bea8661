// SPDX-License-Identifier: BSD-3-Clause
#pragma once

// PCL's console silenced while a reader runs, so that the reason a loader returns is the one
// report of a bad file (PCL's PCD reader prints its own "[pcl::PCDReader::read] ..." lines).

#include <pcl/console/print.h>

namespace pcl_probcollision::io
{
/** \brief Silences PCL's console for its lifetime, unless setVtkMessages (true) asked for the
  * readers' messages. Nested and concurrent instances share one silence: the level before the
  * first is restored when the last ends (the level is process-wide). */
class QuietPclConsole
{
public:
  QuietPclConsole ();
  ~QuietPclConsole ();
  QuietPclConsole (const QuietPclConsole&) = delete;
  QuietPclConsole& operator= (const QuietPclConsole&) = delete;

private:
  bool quiet_;
};

/** \brief Whether setVtkMessages (true) asked for the readers' own messages (VTK's, PCL's). */
bool readerMessagesShown ();
} // namespace pcl_probcollision::io
