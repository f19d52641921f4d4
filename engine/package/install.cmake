# Install rules (included from engine/CMakeLists.txt, after the engine's targets and the CLI).
#   bin/kinesweep
#   lib/libks_*.a, include/kinesweep/<part>/*.hpp, lib/cmake/kinesweep/ (find_package(kinesweep))
#   share/kinesweep/analysis/ (the plot scripts with ksread beside them), share/kinesweep/studies/
#   lib/python3/dist-packages/ (ksread and the modules it uses, for `import ksread`)
#   share/man/man1/kinesweep.1 (help2man, when installed), share/bash-completion/completions/kinesweep
include(CMakePackageConfigHelpers)

set_target_properties(kinesweep_engine PROPERTIES EXPORT_NAME engine)
foreach(part IN LISTS KS_PARTS ITEMS ks_model)
  string(REGEX REPLACE "^ks_" "" short ${part})
  set_target_properties(${part} PROPERTIES EXPORT_NAME ${short})
endforeach()
install(TARGETS kinesweep RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS kinesweep_engine ks_model ${KS_PARTS} EXPORT kinesweepTargets
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

# Analysis: the scripts run from share/kinesweep/analysis (they import ksread from beside them);
# the reader modules are also importable from lib/python3/dist-packages.
file(GLOB KS_ANALYSIS ${PROJECT_SOURCE_DIR}/analysis/*.py)
file(GLOB KS_ANALYSIS_MODULES ${PROJECT_SOURCE_DIR}/analysis/ks*.py)
install(PROGRAMS ${KS_ANALYSIS} DESTINATION ${CMAKE_INSTALL_DATADIR}/kinesweep/analysis)
install(FILES ${PROJECT_SOURCE_DIR}/analysis/README.md DESTINATION ${CMAKE_INSTALL_DATADIR}/kinesweep/analysis)
install(FILES ${KS_ANALYSIS_MODULES} DESTINATION ${CMAKE_INSTALL_LIBDIR}/python3/dist-packages)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/studies/ DESTINATION ${CMAKE_INSTALL_DATADIR}/kinesweep/studies)

# Man page from --help of the program and of each subcommand.
find_program(HELP2MAN help2man)
if(HELP2MAN)
  set(KS_MAN ${PROJECT_BINARY_DIR}/kinesweep.1)
  add_custom_command(OUTPUT ${KS_MAN}
                     COMMAND ${CMAKE_COMMAND} -DKINESWEEP=$<TARGET_FILE:kinesweep> -DHELP2MAN=${HELP2MAN}
                             -DOUT=${KS_MAN} -P ${CMAKE_CURRENT_SOURCE_DIR}/package/man_page.cmake
                     DEPENDS kinesweep ${CMAKE_CURRENT_SOURCE_DIR}/package/man_page.cmake
                     COMMENT "Man page kinesweep.1 (help2man)")
  add_custom_target(kinesweep_man ALL DEPENDS ${KS_MAN})
  install(FILES ${KS_MAN} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
else()
  message(STATUS "kinesweep: help2man not found: no man page")
endif()
install(FILES ${CMAKE_CURRENT_SOURCE_DIR}/package/kinesweep.bash-completion
        DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions RENAME kinesweep)
