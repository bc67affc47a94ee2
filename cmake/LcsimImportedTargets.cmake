# The imported targets lcsim's libraries link that their dependencies do not
# provide under one stable name. Used by the build (LcsimDependencies.cmake)
# and, installed beside lcsimConfig.cmake, by the package, so that the
# exported targets find the same names in a user's project.
#
#   lcsim::urdfdom     urdfdom's include directories and libraries (its config
#                      file gives variables, not a target); needs urdfdom found.
#   PkgConfig::BULLET  pkg-config module bullet-float64 (lcsim::bullet).
#   PkgConfig::IPOPT   pkg-config module ipopt (lcsim::ipopt).
#   lcsim::mujoco_library  MuJoCo's library and header (lcsim::mujoco).
# Each function is a no-op when its target exists already (a project that made
# PkgConfig::BULLET itself from the same module keeps it).

function(lcsim_import_urdfdom)
  if(NOT TARGET lcsim::urdfdom)
    add_library(lcsim::urdfdom INTERFACE IMPORTED)
    set_target_properties(lcsim::urdfdom PROPERTIES
      INTERFACE_INCLUDE_DIRECTORIES "${urdfdom_INCLUDE_DIRS}"
      INTERFACE_SYSTEM_INCLUDE_DIRECTORIES "${urdfdom_INCLUDE_DIRS}"
      INTERFACE_LINK_LIBRARIES "${urdfdom_LIBRARIES}")
  endif()
endfunction()

# Sets <prefix>_FOUND in the caller; the target is PkgConfig::<prefix>.
macro(lcsim_import_pkgconfig prefix module)
  if(TARGET PkgConfig::${prefix})
    set(${prefix}_FOUND TRUE)
  else()
    find_package(PkgConfig QUIET)
    if(PKG_CONFIG_FOUND)
      pkg_check_modules(${prefix} QUIET IMPORTED_TARGET ${module})
    else()
      set(${prefix}_FOUND FALSE)
    endif()
  endif()
endmacro()

# Sets LCSIM_MUJOCO_FOUND in the caller; the target is lcsim::mujoco_library,
# MuJoCo's library and header (Debian: libmujoco-dev), found by name: Debian
# 2.2.2's CMake package (find_package(mujoco)) names a missing include folder
# (/usr/include/libqhull_r) and fails the generate step.
macro(lcsim_import_mujoco)
  if(TARGET lcsim::mujoco_library)
    set(LCSIM_MUJOCO_FOUND TRUE)
  else()
    find_library(LCSIM_MUJOCO_LIBRARY mujoco)
    find_path(LCSIM_MUJOCO_INCLUDE mujoco/mujoco.h)
    if(LCSIM_MUJOCO_LIBRARY AND LCSIM_MUJOCO_INCLUDE)
      add_library(lcsim::mujoco_library UNKNOWN IMPORTED)
      set_target_properties(lcsim::mujoco_library PROPERTIES
        IMPORTED_LOCATION "${LCSIM_MUJOCO_LIBRARY}"
        INTERFACE_INCLUDE_DIRECTORIES "${LCSIM_MUJOCO_INCLUDE}")
      set(LCSIM_MUJOCO_FOUND TRUE)
    else()
      set(LCSIM_MUJOCO_FOUND FALSE)
    endif()
  endif()
endmacro()
