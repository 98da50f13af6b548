# ctest: the README's C example is exactly tests/cmake_consumer/mesh_surface.c (which the
# consumer tests compile and run), so the documented example is a compiled one.
#   cmake -DREADME=... -DEXAMPLE=... -P check_readme.cmake
file(READ "${README}" readme)
file(READ "${EXAMPLE}" example)
string(FIND "${readme}" "```c\n${example}```" pos)
if(pos EQUAL -1)
  message(FATAL_ERROR "README.md's C example differs from ${EXAMPLE}; paste the file into "
                      "the README's ```c block")
endif()
