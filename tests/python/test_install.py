"""Installation (docs/install.md): `cmake --install` into a prefix and the Debian package from
cpack hold a CLI that runs an installed example, the library and its headers, the examples and
docs, and a Python module that a plain python3 imports from the installed place (not the build
tree); a CMake project of one's own finds the library (find_package(kairos)) and runs as the CLI
does. The build is the one under test: its directory is the kairos binary's.
"""

import os
import subprocess
import sys
import unittest

import kairos_testlib as kt

PYTHON = "/usr/bin/python3"
SHORT = ["--set", "run.collisions_per_particle=2", "--set",
         "run.equilibration_collisions_per_particle=0", "--set", "system.particles=500",
         "--set", 'output.progress="never"']


def run(args, **kw):
    return subprocess.run(args, capture_output=True, text=True, timeout=kt.RUN_TIMEOUT, **kw)


CONSUMER_CMAKE = """cmake_minimum_required(VERSION 3.20)
project(own LANGUAGES CXX)
set(CMAKE_CXX_STANDARD 20)
find_package(kairos 0.1 REQUIRED)
add_executable(own main.cpp)
target_link_libraries(own PRIVATE kairos::core)
"""

CONSUMER_MAIN = """#include <cstdio>

#include "io/config.hpp"
#include "run/run.hpp"

int main(int argc, char** argv) {
  if (argc != 3) return 2;
  kairos::Config config = kairos::load_config(argv[1]);
  config.output.directory = argv[2];
  const kairos::RunOutcome outcome = kairos::run_simulation(config);
  std::printf("kairos %s: %s\\n", KAIROS_VERSION,
              outcome.summary["stop_reason"].get<std::string>().c_str());
  return 0;
}
"""


@unittest.skipIf(kt.SANITIZED, "installation is checked on the Release build (make test): the "
                 "sanitized build's binaries are not for installing")
class Install(kt.KairosTestCase):
    def setUp(self):
        super().setUp()
        self.build = os.path.dirname(kt.KAIROS)
        self.module_built = any(f.startswith("kairos.") and f.endswith(".so")
                                for f in os.listdir(os.path.join(self.build, "python"))) \
            if os.path.isdir(os.path.join(self.build, "python")) else False

    def check_tree(self, prefix):
        kairos = os.path.join(prefix, "bin", "kairos")
        result = run([kairos, "--version"])
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("kairos", result.stdout)
        for rel in ("lib/libkairos_core.a", "include/kairos/engine/event_engine.hpp",
                    "include/kairos/core/vec.hpp", "share/kairos/examples/hard_spheres_3d.toml",
                    "share/doc/kairos/docs/config.md", "share/doc/kairos/README.md"):
            self.assertTrue(os.path.isfile(os.path.join(prefix, rel)), rel)
        self.assertFalse(os.path.exists(os.path.join(prefix, "include/kairos/cli")))
        # An installed example runs from the installed CLI.
        out = self.path("run-" + os.path.basename(prefix))
        example = os.path.join(prefix, "share/kairos/examples/hard_spheres_3d.toml")
        result = run([kairos, "run", example, "-o", out] + SHORT, cwd=self.tmp)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(self.summary(out)["stop_reason"], "completed")
        if not self.module_built:
            return
        # A plain python3 imports the installed module: only the installed directory on the
        # path, started away from the build tree.
        site = os.path.join(prefix, "lib", "python3.%d" % sys.version_info.minor,
                            "dist-packages")
        code = ("import kairos, sys; print(kairos.__file__); "
                "assert kairos.__file__.startswith(sys.argv[1]), kairos.__file__")
        result = run([PYTHON, "-c", code, prefix], cwd=self.tmp,
                     env={"PYTHONPATH": site, "PATH": "/usr/bin:/bin"})
        self.assertEqual(result.returncode, 0, result.stderr)

    def test_cmake_install_into_a_prefix(self):
        prefix = self.path("prefix")
        result = run(["cmake", "--install", self.build, "--prefix", prefix])
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        self.check_tree(prefix)

    def test_a_program_of_ones_own_builds_against_the_installed_library(self):
        # find_package(kairos) in a CMake project outside the tree: kairos::core, its headers and
        # dependencies; the program's run is the CLI's bit for bit (the same rounding flags).
        prefix = self.path("prefix")
        result = run(["cmake", "--install", self.build, "--prefix", prefix])
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        project = self.path("consumer")
        os.makedirs(project)
        with open(os.path.join(project, "CMakeLists.txt"), "w") as f:
            f.write(CONSUMER_CMAKE)
        with open(os.path.join(project, "main.cpp"), "w") as f:
            f.write(CONSUMER_MAIN)
        build = os.path.join(project, "build")
        for args in (["cmake", "-S", project, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                      "-DCMAKE_PREFIX_PATH=" + prefix],
                     ["cmake", "--build", build, "-j", "2"]):
            result = run(args, cwd=project)
            self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        config = self.write_config(kt.base_config(particles=256, production=10.0,
                                                  output={"trajectory": False}))
        result = run([os.path.join(build, "own"), config, self.path("own-out")], cwd=self.tmp)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("completed", result.stdout)
        self.run_ok("run", config, "-o", self.path("cli-out"))
        own, cli = self.summary(self.path("own-out")), self.summary(self.path("cli-out"))
        for key in ("sim_time", "events", "kinetic_energy", "compressibility"):
            self.assertEqual(own[key], cli[key], key)

    def test_a_wheel_installs_into_a_virtual_environment(self):
        # scripts/make_wheel.py (the `wheel` target) packs the built module and CLI; pip installs
        # the wheel into a virtual environment, whose python imports the module from its own
        # site-packages and whose bin/ holds the CLI (where kairos.sweep finds it).
        if not self.module_built:
            self.skipTest("the Python module is not built")
        for needed in ("wheel", "venv", "ensurepip"):
            if run([PYTHON, "-c", "import " + needed]).returncode != 0:
                self.skipTest("python3-%s is not installed (scripts/install-deps.sh)" %
                              ("venv" if needed == "ensurepip" else needed))
        module = [f for f in os.listdir(os.path.join(self.build, "python"))
                  if f.startswith("kairos.") and f.endswith(".so")][0]
        result = run([PYTHON, os.path.join(kt.SOURCE_DIR, "scripts", "make_wheel.py"), "--module",
                      os.path.join(self.build, "python", module), "--cli", kt.KAIROS,
                      "--version", "0.1.0", "--out", self.path("dist")])
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        wheel = result.stdout.strip()
        self.assertEqual(os.path.basename(wheel),
                         "kairos-0.1.0-cp3%d-cp3%d-linux_x86_64.whl" % ((sys.version_info.minor,) * 2))
        # With the system's packages (numpy from Debian): pip resolves the dependency offline.
        venv = self.path("venv")
        result = run([PYTHON, "-m", "venv", "--system-site-packages", venv])
        self.assertEqual(result.returncode, 0, result.stderr)
        result = run([os.path.join(venv, "bin", "pip"), "install", "--no-index", wheel])
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        example = os.path.join(kt.SOURCE_DIR, "examples", "hard_spheres_3d.toml")
        code = ("import kairos, sys\n"
                "assert kairos.__file__.startswith(sys.prefix), kairos.__file__\n"
                "sim = kairos.Simulation(sys.argv[1], set=['system.particles=256'])\n"
                "sim.advance(time=0.5)\n"
                "print(sim.positions().shape, sim.time)\n"
                "s = kairos.sweep(sys.argv[1], output=sys.argv[2], workers=1,\n"
                "                 vary={'system.seed': [1]}, set=%r)\n"
                "print(len(s), s[0]['summary']['stop_reason'])\n" % SHORT[1::2])
        result = run([os.path.join(venv, "bin", "python"), "-c", code, example,
                      self.path("venv-sweep")], cwd=self.tmp, env={"PATH": "/usr/bin:/bin"})
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        self.assertIn("(256, 3) 0.5", result.stdout)
        self.assertIn("1 completed", result.stdout)
        result = run([os.path.join(venv, "bin", "kairos"), "run", example, "-o",
                      self.path("venv-run")] + SHORT, cwd=self.tmp)
        self.assertEqual(result.returncode, 0, result.stderr)
        # A plain environment: the module imports and runs without numpy (its arrays need it).
        plain = self.path("plain")
        result = run([PYTHON, "-m", "venv", plain])
        self.assertEqual(result.returncode, 0, result.stderr)
        result = run([os.path.join(plain, "bin", "pip"), "install", "--no-index", "--no-deps",
                      wheel])
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        code = ("import kairos, sys\n"
                "s = kairos.run(sys.argv[1], output=sys.argv[2], set=%r)\n"
                "print(s['stop_reason'])\n" % SHORT[1::2])
        result = run([os.path.join(plain, "bin", "python"), "-c", code, example,
                      self.path("plain-run")], cwd=self.tmp, env={"PATH": "/usr/bin:/bin"})
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        self.assertIn("completed", result.stdout)

    def test_the_debian_package_holds_a_working_tree(self):
        if not os.path.isfile(os.path.join(self.build, "CPackConfig.cmake")):
            self.skipTest("no CPack configuration in this build")
        pkg = self.path("pkg")
        result = run(["cpack", "-G", "DEB", "-B", pkg, "--config",
                      os.path.join(self.build, "CPackConfig.cmake")], cwd=self.build)
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        debs = [f for f in os.listdir(pkg) if f.endswith(".deb")]
        self.assertEqual(len(debs), 1, os.listdir(pkg))
        deb = os.path.join(pkg, debs[0])
        info = run(["dpkg-deb", "--field", deb, "Package", "Depends"]).stdout
        self.assertIn("Package: kairos", info)
        for needed in ("libfmt", "libtomlplusplus", "libstdc++"):
            self.assertIn(needed, info)
        if self.module_built:
            self.assertIn("python3 (>= 3.%d)" % sys.version_info.minor, info)
        root = self.path("root")
        result = run(["dpkg-deb", "-x", deb, root])
        self.assertEqual(result.returncode, 0, result.stderr)
        # Installed under /usr: the module where Debian's python3 looks (sys.path holds
        # /usr/lib/python3.X/dist-packages).
        self.check_tree(os.path.join(root, "usr"))
        if self.module_built:
            listed = run([PYTHON, "-c", "import sys; print('\\n'.join(sys.path))"]).stdout
            self.assertIn("/usr/lib/python3.%d/dist-packages" % sys.version_info.minor,
                          listed.split())


if __name__ == "__main__":
    kt.main()
