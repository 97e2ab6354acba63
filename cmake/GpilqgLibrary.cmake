# gpilqg_add_library(FOLDER SOURCES ... DEPS ...)
# Declares the library of one top-level folder with the project's conventions: target gpilqg_FOLDER,
# alias gpilqg::FOLDER, exported name FOLDER, public headers under FOLDER/include, C++20, warnings.
#
# The libraries are shared: a plugin (core/include/gpilqg/core/plugin.hpp) links gpilqg::core and
# must register into the same SystemRegistry as the program that loads it, which only one
# libgpilqg_core.so in the process gives. The soname carries no version: a plugin built against
# another gpilqg then still loads far enough for its version check to name both versions.
# Installed libraries find each other through RUNPATH $ORIGIN (GPILQG_INSTALL_RPATH_LIB), installed
# programs through $ORIGIN/../lib (GPILQG_INSTALL_RPATH_BIN, the top-level CMakeLists.txt).
function(gpilqg_add_library folder)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  set(target gpilqg_${folder})
  if(NOT ARG_SOURCES)
    # A folder whose sources have not landed yet is a header-only (INTERFACE) target with the same
    # name and alias, so dependants already link against it.
    add_library(${target} INTERFACE)
    add_library(gpilqg::${folder} ALIAS ${target})
    set_target_properties(${target} PROPERTIES EXPORT_NAME ${folder})
    target_compile_features(${target} INTERFACE cxx_std_20)
    target_include_directories(${target} INTERFACE
      $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
      $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
    target_link_libraries(${target} INTERFACE ${ARG_PUBLIC_DEPS})
    install(TARGETS ${target} EXPORT gpilqgTargets)
    install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
    return()
  endif()
  add_library(${target} SHARED ${ARG_SOURCES})
  add_library(gpilqg::${folder} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${folder} OUTPUT_NAME gpilqg_${folder}
    POSITION_INDEPENDENT_CODE ON INSTALL_RPATH "${GPILQG_INSTALL_RPATH_LIB}")
  target_compile_features(${target} PUBLIC cxx_std_20)
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_link_libraries(${target} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE gpilqg_warnings ${ARG_PRIVATE_DEPS})
  install(TARGETS ${target} EXPORT gpilqgTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()
