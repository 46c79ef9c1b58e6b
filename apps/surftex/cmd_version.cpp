// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex version`: versions of surftex and the libraries it was built with.
#include <CGAL/version.h>
#include <Eigen/Core>
#include <OpenImageIO/oiioversion.h>
#include <boost/version.hpp>

#include <cstdio>

#include "surftex/command.h"

namespace surftex::cli {
namespace {
namespace version_command {  // named: the unity build joins these files
SubcommandRegistrar reg{{"version", "Print the versions of surftex and its libraries",
                         [](CLI::App&) -> std::function<int()> {
                           return [] {
                             std::printf("surftex %s (AGPL-3.0-or-later)\n", surftex_version());
                             std::printf("CGAL %s, Eigen %d.%d.%d, OpenImageIO %s, Boost %d.%d\n",
                                         CGAL_VERSION_STR, EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION,
                                         EIGEN_MINOR_VERSION, OIIO_VERSION_STRING,
                                         BOOST_VERSION / 100000, BOOST_VERSION / 100 % 1000);
                             return 0;
                           };
                         }}};
}  // namespace version_command
}  // namespace
}  // namespace surftex::cli
