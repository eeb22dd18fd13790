# Installs the build tree into a fresh prefix and builds the README's consumer example
# against it, as a user of the installed package would: the README's main.cc and
# CMakeLists.txt (the fenced blocks after "<!-- consumer: NAME -->"), find_package(fastcal
# 0.2 CONFIG REQUIRED) with CMAKE_PREFIX_PATH set to the prefix only. Then runs the
# program, the installed fastcal executable and (-DPYTHON=... -DPYTHON_DIR=...) the
# installed Python module.
#
#   cmake -DSOURCE_DIR=... -DBUILD_DIR=... -DWORK_DIR=... [-DGENERATOR=...]
#         -P install_consumer_test.cmake
cmake_minimum_required(VERSION 3.18)

function(run)
  cmake_parse_arguments(RUN "" "WORKING_DIRECTORY;OUTPUT" "COMMAND" ${ARGN})
  if(NOT RUN_WORKING_DIRECTORY)
    set(RUN_WORKING_DIRECTORY ${WORK_DIR})
  endif()
  execute_process(COMMAND ${RUN_COMMAND} WORKING_DIRECTORY ${RUN_WORKING_DIRECTORY}
    RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT code EQUAL 0)
    string(REPLACE ";" " " shown "${RUN_COMMAND}")
    message(FATAL_ERROR "failed (${code}): ${shown}\n${out}")
  endif()
  if(RUN_OUTPUT)
    set(${RUN_OUTPUT} "${out}" PARENT_SCOPE)
  endif()
endfunction()

# The fenced block that follows "<!-- consumer: NAME -->" in the README.
function(readme_block readme name result)
  string(FIND "${readme}" "<!-- consumer: ${name} -->" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "README.md has no block marked <!-- consumer: ${name} -->")
  endif()
  string(SUBSTRING "${readme}" ${at} -1 rest)
  string(REGEX MATCH "```[a-z]*\n(.*)" ignored "${rest}")
  set(rest "${CMAKE_MATCH_1}")
  string(FIND "${rest}" "```" end)
  string(SUBSTRING "${rest}" 0 ${end} block)
  set(${result} "${block}" PARENT_SCOPE)
endfunction()

set(prefix ${WORK_DIR}/prefix)
set(consumer ${WORK_DIR}/consumer)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${consumer})

run(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
foreach(f lib/cmake/fastcal/fastcalConfig.cmake lib/cmake/fastcal/fastcalConfigVersion.cmake
    include/fastcal/statics.h include/fastcal/version.h include/fastcal/internal/statics_core.h)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()

# Only the public headers and the internal ones they include (issue 54): the library's own
# stay out of the prefix.
foreach(f include/fastcal/internal/atomic_file.h include/fastcal/internal/json.h)
  if(EXISTS ${prefix}/${f})
    message(FATAL_ERROR "installed, though no public header includes it: ${f}")
  endif()
endforeach()
# Every installed header compiles on its own against the prefix: nothing it includes was
# left out.
file(GLOB_RECURSE installed RELATIVE ${prefix}/include ${prefix}/include/fastcal/*.h)
set(each "")
foreach(h IN LISTS installed)
  string(APPEND each "#include \"${h}\"\n")
endforeach()
file(MAKE_DIRECTORY ${WORK_DIR}/headers)
file(WRITE ${WORK_DIR}/headers/all.cc "${each}int main() { return 0; }\n")
file(WRITE ${WORK_DIR}/headers/CMakeLists.txt
  "cmake_minimum_required(VERSION 3.18)\nproject(headers CXX)\n"
  "find_package(fastcal CONFIG REQUIRED)\nadd_executable(every_header all.cc)\n"
  "target_link_libraries(every_header PRIVATE fastcal::fastcal)\n")

file(READ ${SOURCE_DIR}/README.md readme)
foreach(name main.cc CMakeLists.txt)
  readme_block("${readme}" ${name} block)
  file(WRITE ${consumer}/${name} "${block}")
endforeach()

set(generator_args)
if(GENERATOR)
  set(generator_args -G ${GENERATOR})
endif()
run(COMMAND ${CMAKE_COMMAND} -S ${consumer} -B ${consumer}/build ${generator_args}
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix})
run(COMMAND ${CMAKE_COMMAND} --build ${consumer}/build)
run(COMMAND ${CMAKE_COMMAND} -S ${WORK_DIR}/headers -B ${WORK_DIR}/headers/build ${generator_args}
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix})
run(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/headers/build)

# The example with the bundled nominal model: six tensions, and the version it was built
# against.
run(COMMAND ${consumer}/build/app ${SOURCE_DIR}/calibration_data/nominal_fast.yaml OUTPUT out)
file(READ ${SOURCE_DIR}/CMakeLists.txt top)
string(REGEX MATCH "project\\(fastcal VERSION ([0-9.]+)" ignored "${top}")
set(version ${CMAKE_MATCH_1})
if(NOT out MATCHES "^fastcal ${version}, exact statics\nT1 = [0-9]+\\.[0-9]+ kN\n.*T6 = ")
  message(FATAL_ERROR "unexpected output of the consumer example:\n${out}")
endif()
message(STATUS "consumer example:\n${out}")

# A bad model file: the library's message naming the file, and exit code 2.
execute_process(COMMAND ${consumer}/build/app ${WORK_DIR}/absent.yaml
  RESULT_VARIABLE code ERROR_VARIABLE err)
if(NOT code EQUAL 2 OR NOT err MATCHES "absent.yaml")
  message(FATAL_ERROR "a missing model file gave exit ${code}: ${err}")
endif()

if(EXISTS ${prefix}/bin/fastcal)
  run(COMMAND ${prefix}/bin/fastcal --version OUTPUT out)
  if(NOT out STREQUAL "fastcal ${version}\n")
    message(FATAL_ERROR "installed fastcal --version: ${out}")
  endif()
endif()
# The installed Python module, imported from elsewhere than the build tree, with its
# documentation.
if(PYTHON)
  set(ENV{PYTHONPATH} ${prefix}/${PYTHON_DIR})
  file(WRITE ${consumer}/import_fastcal.py [[
import pydoc
import sys

import fastcal

assert fastcal.__file__.startswith(sys.argv[1]), fastcal.__file__
assert "position_m" in pydoc.render_doc(fastcal.solve)
print(fastcal.__version__)
]])
  run(COMMAND ${PYTHON} import_fastcal.py ${prefix}/ WORKING_DIRECTORY ${consumer} OUTPUT out)
  if(NOT out STREQUAL "${version}\n")
    message(FATAL_ERROR "installed fastcal.__version__: ${out}")
  endif()
endif()
# The C interface (docs/embedding.md): its C example compiled with pkg-config against the
# installed fastcal.pc alone, and its ctypes example, both run. The C program's cycles and
# locate print; its output must end at the located pose.
file(READ ${SOURCE_DIR}/docs/embedding.md embedding)
set(capi ${WORK_DIR}/capi)
file(MAKE_DIRECTORY ${capi})
foreach(name control_loop.c ctypes_example.py)
  readme_block("${embedding}" ${name} block)
  file(WRITE ${capi}/${name} "${block}")
endforeach()
find_program(PKG_CONFIG pkg-config REQUIRED)
find_program(C_COMPILER NAMES cc gcc clang REQUIRED)
file(GLOB pc_file ${prefix}/lib*/pkgconfig/fastcal.pc ${prefix}/lib/*/pkgconfig/fastcal.pc)
if(NOT pc_file)
  message(FATAL_ERROR "not installed: fastcal.pc under ${prefix}/lib*/pkgconfig")
endif()
get_filename_component(pc_dir "${pc_file}" DIRECTORY)
set(ENV{PKG_CONFIG_PATH} ${pc_dir})
run(COMMAND ${PKG_CONFIG} --cflags --libs fastcal OUTPUT pc_flags)
run(COMMAND ${PKG_CONFIG} --variable=libdir fastcal OUTPUT pc_libdir)
string(STRIP "${pc_flags}" pc_flags)
string(STRIP "${pc_libdir}" pc_libdir)
separate_arguments(pc_flags UNIX_COMMAND "${pc_flags}")
run(COMMAND ${C_COMPILER} -std=c99 -Wall -Wextra -Werror ${capi}/control_loop.c ${pc_flags}
  -Wl,-rpath,${pc_libdir} -o ${capi}/control_loop)
run(COMMAND ${capi}/control_loop OUTPUT out)
if(NOT out MATCHES "^fastcal ${version}, 0 joints\ncycle 0: winch 1 [0-9.]+ m, T1 [0-9.]+ kN.*cycle 4: .*located: 4\\.0000 2\\.0000 145\\.0000 m\n$")
  message(FATAL_ERROR "unexpected output of the C example:\n${out}")
endif()
# A model with encoder offsets (a calibration with lengths writes one): the winch lengths
# the cycle commands locate the pose commanded.
run(COMMAND ${capi}/control_loop ${SOURCE_DIR}/calibration_data/lengths.truth.yaml OUTPUT out)
if(NOT out MATCHES "located: 4\\.0000 2\\.0000 145\\.0000 m\n$")
  message(FATAL_ERROR "the C example with encoder offsets:\n${out}")
endif()
run(COMMAND ${capi}/control_loop ${SOURCE_DIR}/calibration_data/moving_parts.yaml OUTPUT out)
if(NOT out MATCHES "^fastcal ${version}, [1-9] joints\n")
  message(FATAL_ERROR "the C example with moving parts:\n${out}")
endif()
execute_process(COMMAND ${capi}/control_loop ${WORK_DIR}/absent.yaml
  RESULT_VARIABLE code ERROR_VARIABLE err)
if(NOT code EQUAL 2 OR NOT err MATCHES "absent.yaml")
  message(FATAL_ERROR "the C example with a missing model gave exit ${code}: ${err}")
endif()
message(STATUS "C example:\n${out}")
set(ctypes_python ${PYTHON})
if(NOT ctypes_python)
  find_program(ctypes_python python3 REQUIRED)
endif()
file(GLOB c_library ${pc_libdir}/libfastcal_c.so)
run(COMMAND ${ctypes_python} ${capi}/ctypes_example.py ${c_library} OUTPUT out)
if(NOT out MATCHES "^fastcal ${version}\n\\[0.0, 0.0, 145.0\\] T = [0-9. ]+ kN\n.*\\[0.0, 0.0, 260.0\\] [a-z_]+ - solve: .*\ncycle: ok winch 1 [0-9.]+ m, margin to 400 kN [0-9.]+ kN\n$")
  message(FATAL_ERROR "unexpected output of the ctypes example:\n${out}")
endif()
message(STATUS "ctypes example:\n${out}")

# The README's add_subdirectory recipe (the block after "<!-- consumer: subdirectory
# CMakeLists.txt -->"), configured as a parent project that sets no build type: the
# fastcal library gets -O2 (and CMake says so), the parent's own target keeps its flags;
# a parent's build type is left alone. Read from compile_commands.json, not timed.
function(compile_command commands source result)
  string(REGEX MATCH "\"command\": \"[^\"]*${source}[^\"]*\"" found "${commands}")
  if(NOT found)
    message(FATAL_ERROR "no compile command for ${source} in compile_commands.json")
  endif()
  set(${result} "${found}" PARENT_SCOPE)
endfunction()
set(parent ${WORK_DIR}/parent)
file(MAKE_DIRECTORY ${parent})
readme_block("${readme}" "subdirectory CMakeLists.txt" block)
string(REPLACE "path/to/fastcal" "${SOURCE_DIR}" block "${block}")
file(WRITE ${parent}/CMakeLists.txt "${block}")
readme_block("${readme}" main.cc block)
file(WRITE ${parent}/main.cc "${block}")
foreach(build_type "" Debug)
  set(dir ${parent}/build${build_type})
  run(COMMAND ${CMAKE_COMMAND} -S ${parent} -B ${dir} ${generator_args}
    -DCMAKE_BUILD_TYPE=${build_type} -DCMAKE_EXPORT_COMPILE_COMMANDS=ON OUTPUT configured)
  file(READ ${dir}/compile_commands.json commands)
  compile_command("${commands}" "lib/src/statics/statics.cc" library)
  compile_command("${commands}" "main.cc" app)
  if(build_type STREQUAL "")
    if(NOT configured MATCHES "fastcal: the parent project sets no CMAKE_BUILD_TYPE"
        OR NOT library MATCHES " -O2 " OR app MATCHES " -O")
      message(FATAL_ERROR "embedded without a build type, the library is not optimised alone:\n"
        "${library}\n${app}\n${configured}")
    endif()
  elseif(configured MATCHES "fastcal: the parent project" OR library MATCHES " -O2 "
      OR NOT library MATCHES " -g ")
    message(FATAL_ERROR "the parent's ${build_type} build was overridden:\n${library}")
  endif()
endforeach()

file(REMOVE_RECURSE ${WORK_DIR})
