"""The README's MeshLab section says how to build, install and use the plugin as it is built.

check_readme.py README.md
"""
import sys

text = open(sys.argv[1]).read()
assert "\n## MeshLab\n" in text, "README: no '## MeshLab' section"
section = text.split("\n## MeshLab\n", 1)[1].split("\n## ", 1)[0]
for needle in [
    "Tetrahedralize: curved quadratic (curvetet)",  # the filter's name, as in the menu
    "Filters",  # where it is in the GUI
    "Remeshing",  # its class (submenu)
    "-DCURVETET_BUILD_MESHLAB=ON",
    "scripts/fetch-meshlab-source",
    "cmake --install",
    "/usr/lib/x86_64-linux-gnu/meshlab/plugins",
    "libfilter_curvetet.so",
    "meshlabserver",
    "xvfb-run",
    "bindings/meshlab/LICENSE.md",
    "alpha", "featureAngle", "smoothIterations", "optimize", "thorough", "outputFile",
]:
    assert needle in section, f"README's MeshLab section lacks {needle!r}"
print("README: the MeshLab section names the filter, the build, the install and the GUI steps")
