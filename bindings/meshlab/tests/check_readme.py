"""The MeshLab page (docs/meshlab.md) says how to build, install and use the plugin as it is
built.

check_readme.py docs/meshlab.md
"""
import sys

section = open(sys.argv[1]).read()
assert section.startswith("# MeshLab"), f"{sys.argv[1]}: not the MeshLab page"
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
    assert needle in section, f"{sys.argv[1]} lacks {needle!r}"
print(f"{sys.argv[1]}: names the filter, the build, the install and the GUI steps")
