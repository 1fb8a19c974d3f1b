# ctest install_tree: installs the build into a temporary prefix, copies the
# installed tree elsewhere (so neither the build tree nor the install prefix can
# be what it uses), and renders PNG and EXR with the copied bin/sahara and,
# when the Python module is built, with the copied Python package.
#   cmake -DBUILD_DIR=<build tree> [-DOBJCOPY=<objcopy>]
#         [-DPYTHON_EXECUTABLE=<python3> -DPYTHON_INSTALL_DIR=<site-packages relative to the prefix>]
#         -P check_install.cmake
if(NOT BUILD_DIR)
  message(FATAL_ERROR "usage: cmake -DBUILD_DIR=<build tree> -P check_install.cmake")
endif()

set(tmp "$ENV{TMPDIR}")
if(NOT tmp)
  set(tmp /tmp)
endif()
string(RANDOM LENGTH 8 tag)
set(root "${tmp}/sahara_install_test_${tag}")
set(prefix "${root}/prefix")
set(moved "${root}/moved")

function(fail message)
  file(REMOVE_RECURSE "${root}")
  message(FATAL_ERROR "${message}")
endfunction()

execute_process(COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${prefix}"
                RESULT_VARIABLE code OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  fail("cmake --install failed: ${err}")
endif()
if(NOT EXISTS "${prefix}/bin/sahara")
  fail("the install has no bin/sahara")
endif()

# No path of the build tree may be compiled into the installed binary or plugin.
string(REGEX REPLACE "([][+.*()^$?|\\])" "\\\\\\1" build_dir_regex "${BUILD_DIR}")
file(GLOB_RECURSE installed LIST_DIRECTORIES false "${prefix}/*")
foreach(file IN LISTS installed)
  # Debug information (RelWithDebInfo, sanitizer builds) names the compile
  # directory by design and is never read at run time: scan the file without it.
  set(scanned "${file}")
  if(OBJCOPY)
    execute_process(COMMAND "${OBJCOPY}" --strip-debug "${file}" "${root}/scanned"
                    RESULT_VARIABLE stripped OUTPUT_QUIET ERROR_QUIET)
    if(stripped EQUAL 0)
      set(scanned "${root}/scanned")
    endif()
  endif()
  file(STRINGS "${scanned}" hits REGEX "${build_dir_regex}")
  if(hits)
    fail("${file} names the build tree: ${hits}")
  endif()
endforeach()

file(COPY "${prefix}/" DESTINATION "${moved}")
file(REMOVE_RECURSE "${prefix}")
set(sahara "${moved}/bin/sahara")

foreach(format png exr)
  set(out "${root}/out.${format}")
  execute_process(COMMAND "${sahara}" render --width 8 --height 6 --spp 1 --quiet -o "${out}"
                  RESULT_VARIABLE code ERROR_VARIABLE err)
  if(NOT code EQUAL 0 OR NOT EXISTS "${out}")
    fail("the installed sahara did not write ${format} (exit ${code}): ${err}")
  endif()
  file(READ "${out}" magic LIMIT 4 HEX)
  if(format STREQUAL "png" AND NOT magic STREQUAL "89504e47")
    fail("out.png is not a PNG (starts with ${magic})")
  endif()
  if(format STREQUAL "exr" AND NOT magic STREQUAL "762f3101")
    fail("out.exr is not an OpenEXR file (starts with ${magic})")
  endif()
endforeach()

execute_process(COMMAND "${sahara}" --version
                RESULT_VARIABLE code OUTPUT_VARIABLE version)
string(FIND "${version}" "plugin ${moved}/" where)
if(NOT code EQUAL 0 OR where EQUAL -1)
  fail("sahara --version does not report the plugin under ${moved}:\n${version}")
endif()

if(PYTHON_EXECUTABLE)
  set(site "${moved}/${PYTHON_INSTALL_DIR}")
  set(script "import sahara, sys; img = sahara.render(width=8, height=6, spp=1); \
sahara.write_image(sys.argv[1], img); print(sahara.__file__)")
  execute_process(COMMAND "${CMAKE_COMMAND}" -E env --unset=SAHARA_IMAGE_CODEC "PYTHONPATH=${site}"
                          "${PYTHON_EXECUTABLE}" -c "${script}" "${root}/py.png"
                  RESULT_VARIABLE code OUTPUT_VARIABLE where ERROR_VARIABLE err)
  string(FIND "${where}" "${site}/sahara/" inside)
  if(NOT code EQUAL 0 OR inside EQUAL -1 OR NOT EXISTS "${root}/py.png")
    fail("the installed Python package did not import and render from ${site} (exit ${code}): ${where}${err}")
  endif()
endif()

file(REMOVE_RECURSE "${root}")
