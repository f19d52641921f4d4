# cmake -DKINESWEEP=path -DHELP2MAN=path -DOUT=kinesweep.1 -P man_page.cmake
# The man page: help2man on `kinesweep --help`, with each subcommand's --help as a section.
get_filename_component(dir ${OUT} DIRECTORY)
set(include_file ${dir}/kinesweep.h2m)
file(WRITE ${include_file} "[NAME]\nkinesweep \\- parameter-sweep studies of redundant manipulators\n")
foreach(sub run info query sensitivity compare schema robot table4)
  execute_process(COMMAND ${KINESWEEP} ${sub} --help OUTPUT_VARIABLE text RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${KINESWEEP} ${sub} --help failed (${rc})")
  endif()
  string(REPLACE "${KINESWEEP}" "kinesweep" text "${text}")  # CLI11 names the program by argv[0]
  string(REPLACE "\\" "\\\\" text "${text}")
  file(APPEND ${include_file} "\n[COMMAND ${sub}]\n.nf\n${text}\n.fi\n")
endforeach()
file(APPEND ${include_file} "\n[FILES]\nStudy files (TOML) are described in share/kinesweep/studies/README.md; the results\nformat (HDF5) in share/doc/kinesweep/FORMAT.md; the whole tool in share/doc/kinesweep/README.md\n(paths under the installation prefix).\n")
execute_process(COMMAND ${HELP2MAN} --no-info --section=1 --include=${include_file} --output=${OUT} ${KINESWEEP}
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "help2man failed (${rc})")
endif()
