# The imported targets lcsim's libraries link that their dependencies do not
# provide under one stable name. Used by the build (LcsimDependencies.cmake)
# and, installed beside lcsimConfig.cmake, by the package, so that the
# exported targets find the same names in a user's project.
#
#   lcsim::urdfdom     urdfdom's include directories and libraries (its config
#                      file gives variables, not a target); needs urdfdom found.
#   PkgConfig::BULLET  pkg-config module bullet-float64 (lcsim::bullet).
#   PkgConfig::IPOPT   pkg-config module ipopt (lcsim::ipopt).
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
