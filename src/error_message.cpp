// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/error_message.h>

#include <pcl/exceptions.h>

#include <sstream>

namespace pcl_probcollision
{
std::string
errorMessage (const std::exception& e)
{
  const std::string what = e.what ();
  const auto* pcl_error = dynamic_cast<const pcl::PCLException*> (&e);
  if (!pcl_error)
    return what;
  // Rebuild the preamble exactly as pcl::PCLException::createDetailedMessage writes it, and
  // strip it when what() starts with it.
  std::ostringstream preamble;
  if (pcl_error->getFunctionName ())
    preamble << pcl_error->getFunctionName () << " ";
  if (pcl_error->getFileName ())
  {
    preamble << "in " << pcl_error->getFileName () << " ";
    if (pcl_error->getLineNumber () != 0)
      preamble << "@ " << pcl_error->getLineNumber () << " ";
  }
  preamble << ": ";
  const std::string head = preamble.str ();
  return what.compare (0, head.size (), head) == 0 ? what.substr (head.size ()) : what;
}
} // namespace pcl_probcollision
