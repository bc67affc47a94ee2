# Every dependency comes from a Debian 12 package and is found here; a missing
# one stops the configuration with the name of the package that provides it.
include(FindPkgConfig)
include(${CMAKE_CURRENT_LIST_DIR}/LcsimImportedTargets.cmake)

macro(lcsim_require_package name debian)
  find_package(${name} ${ARGN} QUIET)
  if(NOT ${name}_FOUND)
    message(FATAL_ERROR "lcsim: ${name} not found. Install the Debian package: apt-get install ${debian}")
  endif()
endmacro()

macro(lcsim_require_pkgconfig prefix module debian)
  lcsim_import_pkgconfig(${prefix} ${module})
  if(NOT ${prefix}_FOUND)
    message(FATAL_ERROR "lcsim: pkg-config module '${module}' not found. Install the Debian package: apt-get install ${debian}")
  endif()
endmacro()

find_package(PkgConfig QUIET)
if(NOT PKG_CONFIG_FOUND)
  message(FATAL_ERROR "lcsim: pkg-config not found. Install the Debian package: apt-get install pkg-config")
endif()

lcsim_require_package(Eigen3 libeigen3-dev 3.4 NO_MODULE)
lcsim_require_package(yaml-cpp libyaml-cpp-dev)
lcsim_require_package(CLI11 libcli11-dev)
lcsim_require_package(nlohmann_json nlohmann-json3-dev)
lcsim_require_package(urdfdom liburdfdom-dev)
lcsim_import_urdfdom()
lcsim_require_pkgconfig(BULLET bullet-float64 libbullet-dev)
lcsim_require_pkgconfig(IPOPT ipopt coinor-libipopt-dev)
lcsim_require_package(MPI "libopenmpi-dev openmpi-bin" COMPONENTS CXX)
if(LCSIM_BUILD_TESTS)
  lcsim_require_package(GTest libgtest-dev)
endif()
if(LCSIM_BUILD_BENCH)
  lcsim_require_package(benchmark libbenchmark-dev)
endif()

# yaml-cpp 0.7 on Debian exports the plain target name.
if(TARGET yaml-cpp::yaml-cpp AND NOT TARGET yaml-cpp)
  add_library(yaml-cpp ALIAS yaml-cpp::yaml-cpp)
endif()
