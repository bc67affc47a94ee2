# cmake --install (--prefix P): what a user of the library gets.
#   P/include/lcsim/<layer>/*.hpp         #include <lcsim/sim/sim.hpp>
#   P/lib/liblcsim_<layer>.a              one static library per layer
#   P/bin/lcsim                           the command-line program
#   P/share/lcsim/plot.py                 the plotting module (python/lcsim/plot.py)
#   P/share/lcsim/autoregister/*.cpp      registration sources of bullet, ipopt, mujoco
#   P/lib/cmake/lcsim/                    find_package(lcsim [COMPONENTS ...])
#   P/lib/pkgconfig/lcsim*.pc             pkg-config lcsim, lcsim-ipopt, lcsim-bullet,
#                                         lcsim-mujoco
# One CMake component per layer, each its own export file, so that
# find_package(lcsim COMPONENTS sim) reads neither Bullet's nor Ipopt's
# (lcsimConfig.cmake.in loads the components asked for and those below).
# MuJoCo is a component when this build found it (CMakeLists.txt).
include(CMakePackageConfigHelpers)
set(LCSIM_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/lcsim)
set(LCSIM_COMPONENTS core lcp lcs mech impact ipopt sim io circuit scene bullet study app)
set(LCSIM_REGISTERING ipopt bullet)  # the optional components that register methods
if(TARGET lcsim_mujoco)
  list(APPEND LCSIM_COMPONENTS mujoco)
  list(APPEND LCSIM_REGISTERING mujoco)
endif()

foreach(c ${LCSIM_COMPONENTS} all)
  set(name ${c})
  if(c STREQUAL "all")
    set(name lcsim)
  endif()
  set_target_properties(lcsim_${c} PROPERTIES EXPORT_NAME ${name})
  install(TARGETS lcsim_${c} EXPORT lcsim-${name} ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(EXPORT lcsim-${name} NAMESPACE lcsim:: FILE lcsim-${name}-targets.cmake
          DESTINATION ${LCSIM_CMAKE_DIR})
endforeach()
install(DIRECTORY include/lcsim DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS lcsim RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(PROGRAMS python/lcsim/plot.py DESTINATION ${CMAKE_INSTALL_DATADIR}/lcsim)
foreach(c ${LCSIM_REGISTERING})
  install(FILES src/${c}/autoregister/register_${c}.cpp
          DESTINATION ${CMAKE_INSTALL_DATADIR}/lcsim/autoregister)
endforeach()

configure_package_config_file(cmake/lcsimConfig.cmake.in
  ${PROJECT_BINARY_DIR}/lcsimConfig.cmake INSTALL_DESTINATION ${LCSIM_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/lcsimConfigVersion.cmake
  COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/lcsimConfig.cmake ${PROJECT_BINARY_DIR}/lcsimConfigVersion.cmake
        cmake/LcsimImportedTargets.cmake DESTINATION ${LCSIM_CMAKE_DIR})

# pkg-config. A static library drops an object nothing refers to, so the
# registration of an optional component cannot come from its library alone:
# lcsim-<comp>.pc links liblcsim_<comp>_autoregister.a (that one object)
# whole (-Wl,--whole-archive), which adds the methods before main runs.
foreach(c ${LCSIM_REGISTERING})
  add_library(lcsim_${c}_autoregister STATIC src/${c}/autoregister/register_${c}.cpp)
  target_link_libraries(lcsim_${c}_autoregister PRIVATE lcsim_${c})
  install(TARGETS lcsim_${c}_autoregister ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
endforeach()
# Relocatable: the prefix is found from the .pc file's own directory, so
# `cmake --install build --prefix P` works whatever prefix was configured.
file(RELATIVE_PATH LCSIM_PC_TO_PREFIX /p/${CMAKE_INSTALL_LIBDIR}/pkgconfig /p)
foreach(pc lcsim ${LCSIM_REGISTERING})
  if(NOT pc STREQUAL "lcsim")
    set(pc lcsim-${pc})
  endif()
  configure_file(cmake/${pc}.pc.in ${PROJECT_BINARY_DIR}/${pc}.pc @ONLY)
  install(FILES ${PROJECT_BINARY_DIR}/${pc}.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
endforeach()
