# Python: the bodyfit module (python/) and the `python` model plugin (plugins/python), built with
# Debian's pybind11 for the interpreter /usr/bin/python3 — the one the set-up makes the module
# importable from (scripts/build.sh). Skipped under the sanitizers (the interpreter is not
# instrumented) and when pybind11 or the Python headers are missing.
option(BODYFIT_BUILD_PYTHON "Build the Python module and the python model plugin when pybind11 is found" ON)
set(BODYFIT_PYTHON_EXECUTABLE "/usr/bin/python3" CACHE FILEPATH "The Python interpreter the module is built for")
set(BODYFIT_PYTHON OFF)
if(BODYFIT_BUILD_PYTHON AND NOT BODYFIT_SANITIZE)
  if(EXISTS "${BODYFIT_PYTHON_EXECUTABLE}")
    set(Python_EXECUTABLE "${BODYFIT_PYTHON_EXECUTABLE}")
  endif()
  find_package(Python 3.8 QUIET COMPONENTS Interpreter Development.Module Development.Embed)
  set(PYBIND11_FINDPYTHON ON)
  find_package(pybind11 2.10 CONFIG QUIET)
  if(Python_FOUND AND pybind11_FOUND)
    set(BODYFIT_PYTHON ON)
    message(STATUS "bodyfit: Python module for ${Python_EXECUTABLE} (${Python_VERSION}, pybind11 ${pybind11_VERSION})")
  else()
    message(STATUS "bodyfit: no Python module (needs pybind11-dev and python3-dev)")
  endif()
endif()
