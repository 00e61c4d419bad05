# Man pages of the installed prru: prru.1 from `prru --help` and
# `prru --version`, and prru-COMMAND.1 for every command `prru --help`
# lists, from `prru COMMAND --help` (each command answers --help and
# --version). With help2man (Debian package help2man) the pages are
# help2man's; without it, the help text as it is, in a preformatted
# section of a minimal page, so that an install always has its man pages.
# usage: cmake -DPRRU=prru -DOUT=DIR [-DHELP2MAN=help2man] -P prru_man.cmake
cmake_minimum_required(VERSION 3.16) # policies of if() in -P mode
execute_process(COMMAND "${PRRU}" --help OUTPUT_VARIABLE help RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${PRRU} --help: exit ${rc}")
endif()
execute_process(COMMAND "${PRRU}" --version OUTPUT_VARIABLE version_text RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${PRRU} --version: exit ${rc}")
endif()
string(REGEX MATCH "^prru ([^\n ]+)" _ "${version_text}")
set(version "${CMAKE_MATCH_1}")
# The commands: the lines "  NAME  summary" after "commands:".
string(REGEX REPLACE ".*\ncommands:\n" "" listing "${help}")
string(REGEX REPLACE "\n\n.*" "" listing "${listing}")
string(REPLACE "\n" ";" lines "${listing}")
set(commands)
set(summaries)
foreach(line IN LISTS lines)
  if(line MATCHES "^  ([a-z][a-z0-9-]*) +(.*)$")
    list(APPEND commands "${CMAKE_MATCH_1}")
    string(REPLACE ";" "," summary "${CMAKE_MATCH_2}")
    list(APPEND summaries "${summary}")
  endif()
endforeach()
file(REMOVE_RECURSE "${OUT}")
file(MAKE_DIRECTORY "${OUT}")
if(HELP2MAN)
  file(MAKE_DIRECTORY "${OUT}/bin")
endif()

# Text as roff: backslashes doubled, a leading dot or quote kept literal.
function(roff_text text out)
  string(REPLACE "\\" "\\e" text "${text}")
  string(REGEX REPLACE "(^|\n)([.'])" "\\1\\\\&\\2" text "${text}")
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

# One page: NAME (prru or prru-CMD), what (the NAME line), argv (the
# program and its arguments before --help).
function(man_page name what)
  set(argv ${ARGN})
  if(HELP2MAN)
    # help2man runs one program: a wrapper for `prru COMMAND`.
    set(prog "${OUT}/bin/${name}")
    list(JOIN argv "\" \"" quoted)
    file(WRITE "${prog}" "#!/bin/sh\nexec \"${quoted}\" \"$@\"\n")
    file(CHMOD "${prog}" PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE
         WORLD_READ WORLD_EXECUTE)
    execute_process(COMMAND "${HELP2MAN}" --no-info --no-discard-stderr --name=${what}
                            --version-string=${version} --output=${OUT}/${name}.1 "${prog}"
                    RESULT_VARIABLE rc ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "help2man ${name}: ${err}")
    endif()
    return()
  endif()
  execute_process(COMMAND ${argv} --help OUTPUT_VARIABLE text RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${argv} --help: exit ${rc}")
  endif()
  roff_text("${text}" body)
  roff_text("${what}" whatr)
  string(TOUPPER "${name}" upper)
  file(WRITE "${OUT}/${name}.1"
       ".TH ${upper} 1 \"\" \"prru ${version}\" \"User Commands\"\n"
       ".SH NAME\n${name} \\- ${whatr}\n"
       ".SH DESCRIPTION\n.nf\n${body}.fi\n"
       ".SH SEE ALSO\n.BR prru (1)\n")
endfunction()

man_page(prru "dynamics of the 3-PRRU parallel robot from the command line" "${PRRU}")
list(LENGTH commands n)
if(n GREATER 0)
  math(EXPR last "${n} - 1")
  foreach(i RANGE ${last})
    list(GET commands ${i} cmd)
    list(GET summaries ${i} summary)
    man_page(prru-${cmd} "${summary}" "${PRRU}" ${cmd})
  endforeach()
endif()
file(REMOVE_RECURSE "${OUT}/bin")
