# Finds MuJoCo 2.2 (Debian libmujoco-dev) as the target mujoco::mujoco. Used by the project and by
# the installed package's config, so consumers and plugins get the same target.
#
# Debian's mujocoTargets.cmake lists /usr/include/libqhull_r/, which only libqhull-dev provides and
# MuJoCo's public headers never include: keep the include folders that exist.
include(CMakeFindDependencyMacro)
find_dependency(mujoco 2.2 CONFIG)
if(TARGET mujoco::mujoco)
  get_target_property(_gpilqg_mujoco_includes mujoco::mujoco INTERFACE_INCLUDE_DIRECTORIES)
  set(_gpilqg_mujoco_existing)
  foreach(_dir IN LISTS _gpilqg_mujoco_includes)
    if(EXISTS "${_dir}")
      list(APPEND _gpilqg_mujoco_existing "${_dir}")
    endif()
  endforeach()
  set_target_properties(mujoco::mujoco PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_gpilqg_mujoco_existing}")
endif()
