// SPDX-License-Identifier: BSD-3-Clause
// ClassifierParams (classifier_params.h): the documented defaults, validate() naming the
// parameter out of range with its value, the range ends it accepts, and operator== over every
// field.
#include <pcl_probcollision/classifier_params.h>

#include <pcl/exceptions.h>

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <vector>

using namespace pcl_probcollision;

namespace
{
/** \brief A named change to the defaults: what validate() must name, or what operator== must see. */
struct Change
{
  std::string name;
  std::function<void (ClassifierParams&)> apply;
};

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN ();
constexpr double kInf = std::numeric_limits<double>::infinity ();
} // namespace

TEST (ClassifierParams, DefaultsAreTheDocumentedOnes)
{
  const ClassifierParams p;
  EXPECT_EQ (p.kernel, KernelMode::Ladder);
  EXPECT_EQ (p.training, TrainingMode::Robust);
  EXPECT_EQ (p.confidence, 0.9);
  EXPECT_EQ (p.gamma_cap, 0.9);
  EXPECT_EQ (p.C, 1000.0);  // not the reference code's 10 (RESULTS.md, "C10")
  EXPECT_EQ (p.rbf_gamma, 1.0);
  EXPECT_EQ (p.rff_features, 256);
  EXPECT_EQ (p.rff_features_large, 1024);
  EXPECT_EQ (p.rff_seed, 12345u);
  EXPECT_EQ (p.ladder_depth_sigmas, 3.0);
  EXPECT_EQ (p.ladder_fraction, 0.0);
  EXPECT_FALSE (p.exact_points_in_maximum);
  EXPECT_EQ (p.max_iterations, 100);
  EXPECT_EQ (p.loss, Loss::SquaredHinge);
  EXPECT_NO_THROW (p.validate ());
}

TEST (ClassifierParams, ValidateNamesTheParameterOutOfRangeAndItsValue)
{
  const std::vector<Change> cases = {
      {"kernel 9", [] (ClassifierParams& p) { p.kernel = static_cast<KernelMode> (9); }},
      {"training 5", [] (ClassifierParams& p) { p.training = static_cast<TrainingMode> (5); }},
      {"loss 3", [] (ClassifierParams& p) { p.loss = static_cast<Loss> (3); }},
      {"confidence 0.5", [] (ClassifierParams& p) { p.confidence = 0.5; }},
      {"confidence 1", [] (ClassifierParams& p) { p.confidence = 1.0; }},
      {"confidence nan", [] (ClassifierParams& p) { p.confidence = kNaN; }},
      {"gamma_cap 0", [] (ClassifierParams& p) { p.gamma_cap = 0.0; }},
      {"gamma_cap 1", [] (ClassifierParams& p) { p.gamma_cap = 1.0; }},
      {"gamma_cap nan", [] (ClassifierParams& p) { p.gamma_cap = kNaN; }},
      {"C 0", [] (ClassifierParams& p) { p.C = 0.0; }},
      {"C -5", [] (ClassifierParams& p) { p.C = -5.0; }},
      {"C inf", [] (ClassifierParams& p) { p.C = kInf; }},
      {"C nan", [] (ClassifierParams& p) { p.C = kNaN; }},
      {"rbf_gamma 0", [] (ClassifierParams& p) { p.rbf_gamma = 0.0; }},
      {"rbf_gamma inf", [] (ClassifierParams& p) { p.rbf_gamma = kInf; }},
      {"rff_features 7", [] (ClassifierParams& p) { p.rff_features = 7; }},
      {"rff_features_large 255", [] (ClassifierParams& p) { p.rff_features_large = 255; }},
      {"rff_features_large 65537", [] (ClassifierParams& p) { p.rff_features_large = 65537; }},
      {"ladder_depth_sigmas 0", [] (ClassifierParams& p) { p.ladder_depth_sigmas = 0.0; }},
      {"ladder_depth_sigmas nan", [] (ClassifierParams& p) { p.ladder_depth_sigmas = kNaN; }},
      {"ladder_fraction -0.1", [] (ClassifierParams& p) { p.ladder_fraction = -0.1; }},
      {"ladder_fraction 1", [] (ClassifierParams& p) { p.ladder_fraction = 1.0; }},
      {"max_iterations 0", [] (ClassifierParams& p) { p.max_iterations = 0; }},
  };
  for (const Change& c : cases)
  {
    ClassifierParams p;
    c.apply (p);
    try
    {
      p.validate ();
      ADD_FAILURE () << c.name << " did not throw";
    }
    catch (const pcl::BadArgumentException& e)
    {
      const std::string what = e.what ();
      EXPECT_NE (what.find ("[pcl_probcollision::ClassifierParams::validate] " + c.name), std::string::npos)
          << c.name << ": " << what;
    }
  }
}

TEST (ClassifierParams, ValidateNamesTheFirstParameterOutOfRange)
{
  ClassifierParams p;
  p.confidence = 2.0;      // checked before C
  p.C = -1.0;
  p.max_iterations = 0;    // checked last
  try
  {
    p.validate ();
    FAIL () << "did not throw";
  }
  catch (const pcl::BadArgumentException& e)
  {
    const std::string what = e.what ();
    EXPECT_NE (what.find ("confidence 2"), std::string::npos) << what;
    EXPECT_EQ (what.find ("max_iterations"), std::string::npos) << what;
  }
}

TEST (ClassifierParams, ValidateAcceptsTheRangeEnds)
{
  const std::vector<Change> cases = {
      {"confidence just above 0.5", [] (ClassifierParams& p) { p.confidence = 0.5000001; }},
      {"confidence just below 1", [] (ClassifierParams& p) { p.confidence = 0.9999999; }},
      {"gamma_cap just above 0", [] (ClassifierParams& p) { p.gamma_cap = 1e-9; }},
      {"rff_features 8", [] (ClassifierParams& p) { p.rff_features = 8; }},
      {"rff_features_large = rff_features", [] (ClassifierParams& p) { p.rff_features_large = p.rff_features; }},
      {"rff_features_large 65536", [] (ClassifierParams& p) { p.rff_features_large = 65536; }},
      {"ladder_fraction 0.999", [] (ClassifierParams& p) { p.ladder_fraction = 0.999; }},
      {"max_iterations 1", [] (ClassifierParams& p) { p.max_iterations = 1; }},
      {"kernel Linear, training Standard, loss Huber",
       [] (ClassifierParams& p)
       {
         p.kernel = KernelMode::Linear;
         p.training = TrainingMode::Standard;
         p.loss = Loss::Huber;
       }},
      {"kernel RFF", [] (ClassifierParams& p) { p.kernel = KernelMode::RFF; }},
  };
  for (const Change& c : cases)
  {
    ClassifierParams p;
    c.apply (p);
    EXPECT_NO_THROW (p.validate ()) << c.name;
  }
}

TEST (ClassifierParams, EqualityComparesEveryField)
{
  EXPECT_TRUE (ClassifierParams () == ClassifierParams ());
  EXPECT_FALSE (ClassifierParams () != ClassifierParams ());
  const std::vector<Change> cases = {
      {"kernel", [] (ClassifierParams& p) { p.kernel = KernelMode::RFF; }},
      {"training", [] (ClassifierParams& p) { p.training = TrainingMode::Standard; }},
      {"confidence", [] (ClassifierParams& p) { p.confidence = 0.95; }},
      {"gamma_cap", [] (ClassifierParams& p) { p.gamma_cap = 0.5; }},
      {"C", [] (ClassifierParams& p) { p.C = 10.0; }},
      {"rbf_gamma", [] (ClassifierParams& p) { p.rbf_gamma = 2.0; }},
      {"rff_features", [] (ClassifierParams& p) { p.rff_features = 128; }},
      {"rff_features_large", [] (ClassifierParams& p) { p.rff_features_large = 2048; }},
      {"rff_seed", [] (ClassifierParams& p) { p.rff_seed = 1; }},
      {"ladder_depth_sigmas", [] (ClassifierParams& p) { p.ladder_depth_sigmas = 2.0; }},
      {"ladder_fraction", [] (ClassifierParams& p) { p.ladder_fraction = 0.01; }},
      {"exact_points_in_maximum", [] (ClassifierParams& p) { p.exact_points_in_maximum = true; }},
      {"max_iterations", [] (ClassifierParams& p) { p.max_iterations = 50; }},
      {"loss", [] (ClassifierParams& p) { p.loss = Loss::Huber; }},
  };
  for (const Change& c : cases)
  {
    ClassifierParams changed;
    c.apply (changed);
    const ClassifierParams copy = changed;
    EXPECT_FALSE (changed == ClassifierParams ()) << c.name;
    EXPECT_FALSE (ClassifierParams () == changed) << c.name;
    EXPECT_TRUE (changed != ClassifierParams ()) << c.name;
    EXPECT_TRUE (copy == changed) << c.name;
  }
}
