# ctest: the C example of docs/c-api.md (README) is exactly tests/cmake_consumer/mesh_surface.c
# (which the consumer tests compile and run), so the documented example is a compiled one.
#   cmake -DREADME=... -DEXAMPLE=... [-DLANG=cpp] -P check_readme.cmake
if(NOT DEFINED LANG)
  set(LANG c)
endif()
file(READ "${README}" readme)
file(READ "${EXAMPLE}" example)
string(FIND "${readme}" "```${LANG}\n${example}```" pos)
if(pos EQUAL -1)
  message(FATAL_ERROR "${README}'s ${LANG} example differs from ${EXAMPLE}; paste the file "
                      "into its ```${LANG} block")
endif()
