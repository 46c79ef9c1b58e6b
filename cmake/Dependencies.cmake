# Every third-party dependency, found once. All are Debian 12 packages
# (scripts/setup.sh installs them).
set(CGAL_DO_NOT_WARN_ABOUT_CMAKE_BUILD_TYPE TRUE)
find_package(CGAL 5.5 REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(OpenImageIO REQUIRED)
# Debian's OpenImageIO config lists /usr/include/opencv4 even without OpenCV
# installed; drop include folders that do not exist.
foreach(_t OpenImageIO::OpenImageIO OpenImageIO::OpenImageIO_Util)
  if(TARGET ${_t})
    get_target_property(_dirs ${_t} INTERFACE_INCLUDE_DIRECTORIES)
    if(_dirs)
      set(_kept "")
      foreach(_d ${_dirs})
        if(EXISTS "${_d}" OR _d MATCHES "^\\$<")
          list(APPEND _kept "${_d}")
        endif()
      endforeach()
      set_target_properties(${_t} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_kept}")
    endif()
  endif()
endforeach()
find_package(Boost 1.74 REQUIRED COMPONENTS graph)
find_package(TBB REQUIRED)
find_package(CLI11 REQUIRED)
find_package(nlohmann_json REQUIRED)
find_package(nanoflann REQUIRED)
find_package(TinyGLTF REQUIRED)
find_package(Threads REQUIRED)

# TetGen (libtet1.5-dev) ships no CMake config: find header and library.
find_path(TETGEN_INCLUDE_DIR tetgen.h REQUIRED)
find_library(TETGEN_LIBRARY NAMES tet REQUIRED)
if(NOT TARGET surftex_tetgen)
  add_library(surftex_tetgen INTERFACE)
  target_include_directories(surftex_tetgen SYSTEM INTERFACE ${TETGEN_INCLUDE_DIR})
  target_link_libraries(surftex_tetgen INTERFACE ${TETGEN_LIBRARY})
  target_compile_definitions(surftex_tetgen INTERFACE TETLIBRARY)
  add_library(TetGen::tet ALIAS surftex_tetgen)
endif()

# CHOLMOD (libsuitesparse-dev: supernodal Cholesky with AMD/METIS orderings,
# used through Eigen's <Eigen/CholmodSupport>). Debian 12's SuiteSparse 5.12
# ships no CMake config: find the header (in include/suitesparse) and the
# libraries; libcholmod.so brings AMD, COLAMD, METIS, LAPACK and BLAS itself.
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(CHOLMOD_LIBRARY NAMES cholmod REQUIRED)
find_library(SUITESPARSECONFIG_LIBRARY NAMES suitesparseconfig REQUIRED)
# METIS (libmetis-dev, metis.h in /usr/include): the PGP orders its vertex
# graph with METIS_NodeND itself.
find_library(METIS_LIBRARY NAMES metis REQUIRED)
if(NOT TARGET surftex_cholmod)
  add_library(surftex_cholmod INTERFACE)
  target_include_directories(surftex_cholmod SYSTEM INTERFACE ${CHOLMOD_INCLUDE_DIR})
  target_link_libraries(surftex_cholmod INTERFACE ${CHOLMOD_LIBRARY} ${SUITESPARSECONFIG_LIBRARY} ${METIS_LIBRARY} ${CMAKE_DL_LIBS})
  add_library(SuiteSparse::CHOLMOD_surftex ALIAS surftex_cholmod)
endif()
