# Builds the Python module with the project's CMake tree (POINTRAST_PYTHON=ON, only the extension's target)
# and installs python/pointrast with it:
#   python3 -m venv --system-site-packages env && env/bin/pip install --no-build-isolation .
# Needs what scripts/install-deps.sh installs (python3-dev, pybind11-dev, the Vulkan and glslc packages).
# POINTRAST_BUILD_DIR names the build folder: one already configured with -DPOINTRAST_PYTHON=ON for the
# same python3 is built as it is. CMAKE_BUILD_PARALLEL_LEVEL sets the jobs (default: all cores).
import os
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.environ.get("POINTRAST_BUILD_DIR") or os.path.join(os.path.abspath(self.build_temp), "cmake")
        configure = ["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release", "-DPOINTRAST_TESTS=OFF",
                     "-DPOINTRAST_PYTHON=ON", "-DPython_EXECUTABLE=" + sys.executable]
        if shutil.which("ccache"):
            configure.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
        if not os.path.exists(os.path.join(build, "CMakeCache.txt")):
            subprocess.check_call(configure)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        subprocess.check_call(["cmake", "--build", build, "--target", "pointrast_python", "pointrast", "-j", jobs])
        package = os.path.join(build, "python", "pointrast")
        built = [f for f in os.listdir(package) if f.startswith("_core") and f.endswith(".so")]
        if len(built) != 1:
            raise RuntimeError("the CMake build left no single _core extension in " + package)
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(os.path.join(package, built[0]), target)
        # The command-line program goes along: pointrast.show() runs its `serve`.
        program = os.path.join(os.path.dirname(target), "_bin", "pointrast")
        os.makedirs(os.path.dirname(program), exist_ok=True)
        shutil.copyfile(os.path.join(build, "pointrast"), program)
        os.chmod(program, 0o755)


setup(
    name="pointrast",
    version="0.1.0",
    description="Render point clouds by software rasterization in compute shaders (Vulkan)",
    packages=["pointrast"],
    package_dir={"": "python"},
    ext_modules=[Extension("pointrast._core", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    install_requires=["numpy"],
    python_requires=">=3.9",
    zip_safe=False,
)
