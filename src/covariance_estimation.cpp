// SPDX-License-Identifier: BSD-3-Clause
#include <pcl_probcollision/covariance_estimation.h>
#include <pcl_probcollision/impl/covariance_estimation.hpp>

#include <pcl/impl/instantiate.hpp>

#ifndef PCL_NO_PRECOMPILE
PCL_INSTANTIATE (CovarianceEstimation, PCL_PROBCOLLISION_POINT_TYPES)
#endif
