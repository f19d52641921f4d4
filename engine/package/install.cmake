# Install rules (included from engine/CMakeLists.txt, after the engine's targets and the CLI).
#   bin/kinesweep (and bin/kinesweep-mpi with MPI)
#   lib/libks_*.a, include/kinesweep/<part>/*.hpp, lib/cmake/kinesweep/ (find_package(kinesweep))
#   share/kinesweep/studies/, share/doc/kinesweep/analysis.md
#   lib/python3.X/dist-packages/kinesweep/ (the Python package: `python3 -m kinesweep.plot_cases FILE`)
#   share/man/man1/kinesweep.1 (package/man_page.py, when Python 3 is found), share/bash-completion/completions/kinesweep
include(CMakePackageConfigHelpers)

set_target_properties(kinesweep_engine PROPERTIES EXPORT_NAME engine)
foreach(part IN LISTS KS_PARTS ITEMS ks_model ks_hdf5)
  string(REGEX REPLACE "^ks_" "" short ${part})
  set_target_properties(${part} PROPERTIES EXPORT_NAME ${short})
endforeach()
install(TARGETS kinesweep RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
if(TARGET kinesweep-mpi)  # a run started by an MPI launcher continues in it (engine/cli/main.cpp)
  install(TARGETS kinesweep-mpi RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
install(TARGETS kinesweep_engine ks_model ks_hdf5 ${KS_PARTS} EXPORT kinesweepTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/kinesweep
        FILES_MATCHING PATTERN "*.hpp" PATTERN "cli" EXCLUDE PATTERN "package" EXCLUDE)

set(KS_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/kinesweep)
install(EXPORT kinesweepTargets NAMESPACE kinesweep:: DESTINATION ${KS_CMAKE_DIR})
get_property(KS_HAVE_MPI GLOBAL PROPERTY KINESWEEP_HAVE_MPI)
if(NOT KS_HAVE_MPI)
  set(KS_HAVE_MPI FALSE)
endif()
configure_package_config_file(${CMAKE_CURRENT_SOURCE_DIR}/package/kinesweepConfig.cmake.in
                              ${CMAKE_CURRENT_BINARY_DIR}/kinesweepConfig.cmake INSTALL_DESTINATION ${KS_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/kinesweepConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/kinesweepConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/kinesweepConfigVersion.cmake
        DESTINATION ${KS_CMAKE_DIR})

# Analysis: the Python package `kinesweep` (analysis/kinesweep), into the directory Debian's python3
# searches for the prefix given at install time (`cmake --install --prefix P` included):
# lib/python3/dist-packages under /usr, lib/python3.X/dist-packages under any other prefix (e.g.
# /usr/local; X from /usr/bin/python3, else the python3 on PATH). KINESWEEP_PYTHON_DIR (relative to
# the prefix) overrides it.
set(KINESWEEP_PYTHON_DIR "" CACHE STRING "where cmake --install puts the Python package, relative to the prefix (empty: Debian's directory for the prefix)")
find_program(KS_SYSTEM_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
if(NOT KS_SYSTEM_PYTHON)
  find_program(KS_SYSTEM_PYTHON NAMES python3)
endif()
install(CODE "
  set(ks_py_dir \"${KINESWEEP_PYTHON_DIR}\")
  if(NOT ks_py_dir)
    set(ks_py_dir lib/python3/dist-packages)
    if(NOT CMAKE_INSTALL_PREFIX STREQUAL \"/usr\" AND EXISTS \"${KS_SYSTEM_PYTHON}\")
      execute_process(COMMAND \"${KS_SYSTEM_PYTHON}\" -c \"import sys; print('%d.%d' % sys.version_info[:2])\"
                      OUTPUT_VARIABLE ks_py_version OUTPUT_STRIP_TRAILING_WHITESPACE)
      set(ks_py_dir lib/python\${ks_py_version}/dist-packages)
    endif()
  endif()
  file(INSTALL \"${PROJECT_SOURCE_DIR}/analysis/kinesweep\" DESTINATION \"\${CMAKE_INSTALL_PREFIX}/\${ks_py_dir}\"
       FILES_MATCHING PATTERN \"*.py\" PATTERN \"__pycache__\" EXCLUDE)
")
install(FILES ${PROJECT_SOURCE_DIR}/analysis/README.md DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/kinesweep RENAME analysis.md)
install(FILES ${PROJECT_SOURCE_DIR}/engine/store/FORMAT.md ${PROJECT_SOURCE_DIR}/README.md
              ${PROJECT_SOURCE_DIR}/engine/package/LICENSE ${PROJECT_SOURCE_DIR}/engine/package/CITATION.cff
        DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/kinesweep)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/studies/ DESTINATION ${CMAKE_INSTALL_DATADIR}/kinesweep/studies)

# Man page from --help of the program and of each subcommand (package/man_page.py, standard library only).
find_package(Python3 COMPONENTS Interpreter)
if(Python3_Interpreter_FOUND)
  set(KS_MAN ${PROJECT_BINARY_DIR}/kinesweep.1)
  add_custom_command(OUTPUT ${KS_MAN}
                     COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/package/man_page.py
                             --kinesweep $<TARGET_FILE:kinesweep> --out ${KS_MAN} --source-dir ${PROJECT_SOURCE_DIR}
                     DEPENDS kinesweep ${CMAKE_CURRENT_SOURCE_DIR}/package/man_page.py
                     COMMENT "Man page kinesweep.1")
  add_custom_target(kinesweep_man ALL DEPENDS ${KS_MAN})
  install(FILES ${KS_MAN} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
else()
  message(STATUS "kinesweep: no Python 3 interpreter found: no man page")
endif()
install(FILES ${CMAKE_CURRENT_SOURCE_DIR}/package/kinesweep.bash-completion
        DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions RENAME kinesweep)
