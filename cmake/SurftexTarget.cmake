# Per-target build hygiene: warnings and sanitizers only on our own targets,
# never directory-wide (third-party headers are SYSTEM includes).
function(surftex_target_options target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wno-unused-parameter)
  if(SURFTEX_PCH)  # say so when a precompiled header cannot be used
    target_compile_options(${target} PRIVATE -Winvalid-pch)
  endif()
  if(SURFTEX_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
    # GCC 12's -Wmaybe-uninitialized misfires on the sanitizers' instrumented
    # code (std::vector::assign, std::regex, CGAL's Epic_converter: 18 in a CI log).
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
      target_compile_options(${target} PRIVATE -Wno-maybe-uninitialized)
    endif()
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
endfunction()

# A module library built from every .cpp in its folder: one algorithm per
# header/source pair, so adding an algorithm needs no CMake edit.
# EXCLUDE names sources of the folder that are built elsewhere.
function(surftex_add_module name)
  cmake_parse_arguments(ARG "" "" "DEPS;EXCLUDE;SUBDIRS" ${ARGN})
  file(GLOB _srcs CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/*.cpp")
  foreach(_d ${ARG_SUBDIRS})  # one method's files (e.g. texture/patches/)
    file(GLOB _sub CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/${_d}/*.cpp")
    list(APPEND _srcs ${_sub})
  endforeach()
  foreach(_x ${ARG_EXCLUDE})
    list(REMOVE_ITEM _srcs "${CMAKE_CURRENT_SOURCE_DIR}/${_x}")
  endforeach()
  if(_srcs)
    add_library(surftex_${name} STATIC ${_srcs})
    target_include_directories(surftex_${name} PUBLIC "${PROJECT_SOURCE_DIR}/src")
    target_link_libraries(surftex_${name} PUBLIC ${ARG_DEPS})
    surftex_target_options(surftex_${name})
    surftex_unity(surftex_${name})
    add_library(surftex::${name} ALIAS surftex_${name})
  else()  # a module with no sources yet
    add_library(surftex_${name} INTERFACE)
    target_include_directories(surftex_${name} INTERFACE "${PROJECT_SOURCE_DIR}/src")
    target_link_libraries(surftex_${name} INTERFACE ${ARG_DEPS})
    add_library(surftex::${name} ALIAS surftex_${name})
  endif()
endfunction()

# SURFTEX_PCH: one precompiled header for the whole build, made by
# surftex_geometry (CGAL's kernel and Surface_mesh, Eigen, nlohmann/json: the
# headers most sources include) and reused by every other target. GCC's
# precompiled header of mesh.h alone is about 560 MB; one per target filled the
# CI machine's disk (docs/decisions/504-first-build.md, 801-ci-time.md).
set(SURFTEX_PCH_HEADERS "${PROJECT_SOURCE_DIR}/src/geometry/mesh.h" <Eigen/Dense> <nlohmann/json.hpp>)
function(surftex_precompile target)
  if(NOT SURFTEX_PCH)
    return()
  endif()
  if(target STREQUAL "surftex_geometry")
    target_precompile_headers(${target} PRIVATE ${SURFTEX_PCH_HEADERS})
  else()
    target_precompile_headers(${target} REUSE_FROM surftex_geometry)
  endif()
endfunction()

# SURFTEX_UNITY: the target's sources joined 8 at a time (CMake's unity
# build). Sources keep their file-local names apart: no two sources of one
# target may define the same name in an anonymous namespace.
# GCC's -Wsubobject-linkage (a class with a field of an anonymous-namespace
# type, "defined in a header") fires on every such class of a source included
# into a unity batch, where the source is no longer the main file; each source
# is still compiled once, so the multiple definitions the warning guards
# against cannot happen. Off for unity targets only (13 warnings on a first build).
function(surftex_unity target)
  if(SURFTEX_UNITY)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
      target_compile_options(${target} PRIVATE -Wno-subobject-linkage)
    endif()
  endif()
endfunction()
