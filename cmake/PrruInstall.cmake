# Installation: `cmake --install BUILD [--prefix DIR]` writes
#   bin/prru                  the command-line tool
#   lib/libprru.so*           runtime + kernels, shared            (prru::prru)
#   lib/libprru.a             runtime + kernels, static: -lprru of
#                             `pkg-config --static --libs prru`
#   lib/libprru_runtime.a     the runtime, static, with the next   (prru::prru_static)
#   lib/libprru_kernels.a     the generated kernels alone, libm    (prru::kernels)
#   include/prru/*.h          runtime and generated headers
#   lib/cmake/prru/           find_package(prru): config, version, targets
#   lib/pkgconfig/prru.pc     pkg-config: -lprru, shared, or static with
#                             --static (adds GSL, libpthread, libm)
#   share/prru/MODEL.json     the model file the kernels come from
#   lib/python3/dist-packages/prru/   the Python binding (PRRU_INSTALL_PYTHONDIR),
#                             finding ../../../LIBDIR/libprru.so by itself
#                             (prru/_installed.py): PYTHONPATH=that directory
#   share/man/man1/prru.1, prru-COMMAND.1   man pages (help2man when found)
# (lib is GNUInstallDirs' CMAKE_INSTALL_LIBDIR.)
#
# The runtime's structs are the same for every model (prru_sizes.h); the
# specialised kernels and prru_model_default are of one model, named in the
# package by prru_MODEL_FILE / prru_MODEL_SHA256 and in prru.pc by the
# variables model_file / model_sha256, whose number of limbs the install's
# runtime computes with.
include(CMakePackageConfigHelpers)

set(PRRU_INSTALL_INCLUDEDIR "${CMAKE_INSTALL_INCLUDEDIR}/prru")
set(PRRU_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/prru")
get_filename_component(PRRU_MODEL_BASENAME "${PRRU_MODEL}" NAME)

# Exported names: prru::prru (shared), prru::prru_static, prru::kernels;
# the same names are aliases in the build tree, so a parent project that
# does add_subdirectory(prru) writes what a find_package(prru) user writes.
set_target_properties(prru_shared PROPERTIES EXPORT_NAME prru)
set_target_properties(prru_runtime PROPERTIES EXPORT_NAME prru_static)
set_target_properties(prru_kernels PROPERTIES EXPORT_NAME kernels)
add_library(prru::prru ALIAS prru_shared)
add_library(prru::prru_static ALIAS prru_runtime)
add_library(prru::kernels ALIAS prru_kernels)

install(TARGETS prru_shared prru_runtime prru_kernels EXPORT prruTargets
        RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}"
        LIBRARY DESTINATION "${CMAKE_INSTALL_LIBDIR}"
        ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}"
        INCLUDES DESTINATION "${PRRU_INSTALL_INCLUDEDIR}")
# libprru.a, the static twin of libprru.so under the name -lprru, so that
# `pkg-config --static --libs prru` links: the objects prru_runtime and
# prru_kernels are built from, archived once more (nothing is compiled
# again). Not exported: CMake users link prru::prru_static.
add_library(prru_archive STATIC $<TARGET_OBJECTS:prru_runtime_objects>
            $<TARGET_OBJECTS:prru_kernel_objects>)
set_target_properties(prru_archive PROPERTIES OUTPUT_NAME prru LINKER_LANGUAGE C)
install(TARGETS prru_archive ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}")
# Whole directories, so that a header added to runtime/include or a file
# pair added to the generator's output is installed without a change here.
install(DIRECTORY "${PROJECT_SOURCE_DIR}/runtime/include/"
        DESTINATION "${PRRU_INSTALL_INCLUDEDIR}" FILES_MATCHING PATTERN "*.h")
install(DIRECTORY "${PRRU_GEN_DIR}/"
        DESTINATION "${PRRU_INSTALL_INCLUDEDIR}" FILES_MATCHING PATTERN "*.h")
install(FILES "${PRRU_MODEL}" DESTINATION "${CMAKE_INSTALL_DATADIR}/prru")
# The generator and its templates, for `prru gen` (Python 3 standard library
# only): share/prru/gen/prru_gen.py finds share/prru/templates as in the
# source tree. Its unit tests stay behind.
install(FILES "${PROJECT_SOURCE_DIR}/gen/prru_gen.py" "${PROJECT_SOURCE_DIR}/gen/prru_mjcf.py"
        DESTINATION "${CMAKE_INSTALL_DATADIR}/prru/gen")
install(DIRECTORY "${PROJECT_SOURCE_DIR}/gen/prrugen/" DESTINATION "${CMAKE_INSTALL_DATADIR}/prru/gen/prrugen"
        FILES_MATCHING PATTERN "*.py")
install(DIRECTORY "${PROJECT_SOURCE_DIR}/templates/" DESTINATION "${CMAKE_INSTALL_DATADIR}/prru/templates")

install(EXPORT prruTargets NAMESPACE prru:: FILE prruTargets.cmake
        DESTINATION "${PRRU_INSTALL_CMAKEDIR}")
configure_package_config_file("${CMAKE_CURRENT_LIST_DIR}/prruConfig.cmake.in"
  "${PROJECT_BINARY_DIR}/prruConfig.cmake"
  INSTALL_DESTINATION "${PRRU_INSTALL_CMAKEDIR}")
# 0.x: a new minor version may change the API.
write_basic_package_version_file("${PROJECT_BINARY_DIR}/prruConfigVersion.cmake"
  COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/prruConfig.cmake"
              "${PROJECT_BINARY_DIR}/prruConfigVersion.cmake"
        DESTINATION "${PRRU_INSTALL_CMAKEDIR}")

# prru.pc carries absolute paths, and the prefix is only known when
# installing (cmake --install --prefix DIR overrides CMAKE_INSTALL_PREFIX):
# everything but the prefix is filled in now, the prefix by the install
# script. A path in prru.pc is escaped as pkg-config reads it (pkgconf
# splits Cflags and Libs like a shell: a backslash before a space, tab,
# quote, backslash or '#' keeps it in the word, and pkg-config prints it so
# escaped, for the shell that runs the compiler: a Makefile's recipe, or
# `eval`). prru_pc_escape.cmake escapes pc_path in place, for the paths
# known now and for the prefix at install time (one text for both).
file(WRITE "${PROJECT_BINARY_DIR}/prru_pc_escape.cmake" [=[
string(REPLACE "\\" "\\\\" pc_path "${pc_path}")
foreach(c " " "\t" "\"" "'" "#")
  string(REPLACE "${c}" "\\${c}" pc_path "${pc_path}")
endforeach()
]=])
foreach(kind LIB INCLUDE)
  if(IS_ABSOLUTE "${CMAKE_INSTALL_${kind}DIR}")
    set(pc_path "${CMAKE_INSTALL_${kind}DIR}")
    include("${PROJECT_BINARY_DIR}/prru_pc_escape.cmake")
    set(PRRU_PC_${kind}DIR "${pc_path}")
  else()
    set(PRRU_PC_${kind}DIR "\${prefix}/${CMAKE_INSTALL_${kind}DIR}")
  endif()
endforeach()
set(PRRU_PC_PREFIX "@PRRU_PC_PREFIX@") # left for the install step
configure_file("${CMAKE_CURRENT_LIST_DIR}/prru.pc.in" "${PROJECT_BINARY_DIR}/prru.pc.in" @ONLY)
if(IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
  set(prru_pc_destination "${CMAKE_INSTALL_LIBDIR}/pkgconfig")
else()
  set(prru_pc_destination "\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_LIBDIR}/pkgconfig")
endif()
# file(INSTALL) adds DESTDIR, the manifest entry and the "Installing:" line.
install(CODE "
  set(pc_path \"\${CMAKE_INSTALL_PREFIX}\")
  include(\"${PROJECT_BINARY_DIR}/prru_pc_escape.cmake\")
  set(PRRU_PC_PREFIX \"\${pc_path}\")
  configure_file(\"${PROJECT_BINARY_DIR}/prru.pc.in\" \"${PROJECT_BINARY_DIR}/pkgconfig/prru.pc\" @ONLY)
  file(INSTALL \"${PROJECT_BINARY_DIR}/pkgconfig/prru.pc\" DESTINATION \"${prru_pc_destination}\")")

# ---- the Python binding ----
# Into the directory Debian's python3 searches under /usr, relative to the
# prefix (another prefix: PYTHONPATH=PREFIX/lib/python3/dist-packages).
set(PRRU_INSTALL_PYTHONDIR "lib/python3/dist-packages" CACHE STRING
    "where cmake --install puts the Python package prru (relative: under the prefix)")
install(DIRECTORY "${PROJECT_SOURCE_DIR}/python/prru/" DESTINATION "${PRRU_INSTALL_PYTHONDIR}/prru"
        FILES_MATCHING PATTERN "*.py" PATTERN "__pycache__" EXCLUDE)
# prru/_installed.py: where the installed library is, relative to the
# package when both directories are under the prefix (the install can be
# moved, or staged with DESTDIR), else absolute.
if(IS_ABSOLUTE "${PRRU_INSTALL_PYTHONDIR}" OR IS_ABSOLUTE "${CMAKE_INSTALL_LIBDIR}")
  set(prru_py_lib "${CMAKE_INSTALL_FULL_LIBDIR}/libprru.so")
  set(prru_py_relative False)
else()
  file(RELATIVE_PATH prru_py_lib "/prefix/${PRRU_INSTALL_PYTHONDIR}/prru" "/prefix/${CMAKE_INSTALL_LIBDIR}/libprru.so")
  set(prru_py_relative True)
endif()
file(WRITE "${PROJECT_BINARY_DIR}/python/_installed.py"
     "\"\"\"Written by cmake --install: where the installed libprru.so is.\"\"\"\n"
     "LIBRARY = \"${prru_py_lib}\"\n"
     "RELATIVE = ${prru_py_relative}  # LIBRARY relative to this package's directory\n")
install(FILES "${PROJECT_BINARY_DIR}/python/_installed.py" DESTINATION "${PRRU_INSTALL_PYTHONDIR}/prru")

# ---- man pages ----
find_program(PRRU_HELP2MAN help2man)
set(prru_man_dir "${PROJECT_BINARY_DIR}/man")
add_custom_command(OUTPUT "${prru_man_dir}/prru.1"
  COMMAND "${CMAKE_COMMAND}" -DPRRU=$<TARGET_FILE:prru> "-DOUT=${prru_man_dir}"
          "-DHELP2MAN=$<$<BOOL:${PRRU_HELP2MAN}>:${PRRU_HELP2MAN}>"
          -P "${CMAKE_CURRENT_LIST_DIR}/prru_man.cmake"
  DEPENDS prru "${CMAKE_CURRENT_LIST_DIR}/prru_man.cmake"
  COMMENT "Man pages of prru")
add_custom_target(prru_man ALL DEPENDS "${prru_man_dir}/prru.1")
install(DIRECTORY "${prru_man_dir}/" DESTINATION "${CMAKE_INSTALL_MANDIR}/man1" FILES_MATCHING PATTERN "*.1")
