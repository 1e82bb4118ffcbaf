# Third-party dependencies, all Debian 12 packages (see scripts/setup.sh).
find_package(OpenMesh CONFIG REQUIRED)   # Debian's config has no version file: ask for none
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(fmt REQUIRED)
find_package(spdlog REQUIRED)
find_package(TBB REQUIRED)
find_package(tomlplusplus REQUIRED)
find_package(CLI11 REQUIRED)
find_package(PNG REQUIRED)
find_package(Threads REQUIRED)

# CHOLMOD has no CMake config in Debian 12.
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(CHOLMOD_LIBRARY cholmod REQUIRED)
add_library(bodyfit::cholmod INTERFACE IMPORTED)
target_include_directories(bodyfit::cholmod INTERFACE ${CHOLMOD_INCLUDE_DIR})
target_link_libraries(bodyfit::cholmod INTERFACE ${CHOLMOD_LIBRARY})

# TetGen 1.5 (AGPL): only the thermal plugin links it.
find_path(TETGEN_INCLUDE_DIR tetgen.h)
find_library(TETGEN_LIBRARY tet)
if(TETGEN_INCLUDE_DIR AND TETGEN_LIBRARY)
  add_library(bodyfit::tetgen INTERFACE IMPORTED)
  target_include_directories(bodyfit::tetgen INTERFACE ${TETGEN_INCLUDE_DIR})
  target_link_libraries(bodyfit::tetgen INTERFACE ${TETGEN_LIBRARY})
  target_compile_definitions(bodyfit::tetgen INTERFACE TETLIBRARY)
endif()

# GDAL is required (the GIS formats: GeoTIFF rasters, coordinate systems, reprojection, vector
# layers; loaded as a module on first use, never linked into the core). -DBODYFIT_WITH_GDAL=OFF
# builds without those formats on purpose.
set(BODYFIT_HAVE_GDAL OFF)
if(BODYFIT_WITH_GDAL)
  find_package(GDAL CONFIG QUIET)
  if(NOT GDAL_FOUND)
    find_package(GDAL QUIET)
  endif()
  if(NOT GDAL_FOUND)
    message(FATAL_ERROR "bodyfit: GDAL not found (Debian: apt-get install libgdal-dev, which scripts/setup.sh "
                        "does); or configure with -DBODYFIT_WITH_GDAL=OFF to build without the GIS formats")
  endif()
  set(BODYFIT_HAVE_GDAL ON)
endif()
message(STATUS "bodyfit: GeoTIFF support through GDAL: ${BODYFIT_HAVE_GDAL}")

# Cairo is optional: fire maps (bodyfit map, fire_map.png) are drawn with it, in a module.
set(BODYFIT_HAVE_CAIRO OFF)
if(BODYFIT_WITH_CAIRO)
  find_package(PkgConfig QUIET)
  if(PKG_CONFIG_FOUND)
    pkg_check_modules(CAIRO QUIET IMPORTED_TARGET cairo)
    if(CAIRO_FOUND)
      set(BODYFIT_HAVE_CAIRO ON)
    endif()
  endif()
endif()
message(STATUS "bodyfit: fire maps through Cairo: ${BODYFIT_HAVE_CAIRO}")
# MPI is optional: `bodyfit ensemble` spreads members over ranks through a module loaded only
# under an MPI launcher (app/mpi), never linked into the core or the program.
set(BODYFIT_HAVE_MPI OFF)
if(BODYFIT_WITH_MPI)
  set(MPI_CXX_SKIP_MPICXX TRUE)  # the C API from C++, not the removed C++ bindings
  find_package(MPI COMPONENTS CXX QUIET)
  if(MPI_CXX_FOUND)
    set(BODYFIT_HAVE_MPI ON)
  endif()
endif()
message(STATUS "bodyfit: MPI ensembles: ${BODYFIT_HAVE_MPI}")
