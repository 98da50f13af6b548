# ctest gmsh_readme: docs/gmsh.md (README) shows each example file verbatim in a fenced block, so the
# documented examples are the ones the tests compile and run.
#   cmake -DREADME=... "-DEXAMPLES=file|lang;file|lang" -P check_readme.cmake
file(READ "${README}" readme)
foreach(e IN LISTS EXAMPLES)
  string(REPLACE "|" ";" e "${e}")
  list(GET e 0 path)
  list(GET e 1 lang)
  file(READ "${path}" example)
  string(FIND "${readme}" "```${lang}\n${example}```" pos)
  if(pos EQUAL -1)
    message(FATAL_ERROR "${README}'s ${lang} example differs from ${path}; paste the file into a ```${lang} block")
  endif()
endforeach()
