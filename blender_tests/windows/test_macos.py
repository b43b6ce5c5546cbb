"""The macOS modules cross-built with zig (scripts/macos.py), checked as far as this machine can:
their Mach-O headers. UNTESTED beyond that: none has been loaded by a macOS Python. Each is the
right architecture, needs only the system's libSystem (GLPK, NLopt and libc++ are linked in),
exports Python's entry point PyInit__wiresculpt, says macOS 11.0 as its minimum, and the arm64 one
carries the (ad-hoc) code signature arm64 macOS requires. Skipped when this tree's modules are not
in the cache (scripts/package builds them; the suite builds nothing for macOS)."""
import os
import subprocess
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "scripts"))

import macos  # noqa: E402

CPU = {"aarch64": "arm64", "x86_64": "x86_64"}


def objdump(*args):
    return subprocess.run(["llvm-objdump", "--macho", *args], capture_output=True, text=True, check=True).stdout


class MacModules(unittest.TestCase):
    def modules(self):
        found = {(a, m): macos.cached_module(a, m) for a in macos.ARCHS for m in ("3.11", "3.13")}
        if None in found.values():
            self.skipTest("no macOS modules of this source tree in the cache: scripts/package builds them")
        return found

    def test_headers(self):
        for (arch, minor), path in self.modules().items():
            with self.subTest(arch=arch, python=minor):
                self.assertTrue(path.endswith(f"_wiresculpt.cpython-{minor.replace('.', '')}-darwin.so"), path)
                with open(path, "rb") as f:
                    self.assertEqual(f.read(4), b"\xcf\xfa\xed\xfe")  # MH_MAGIC_64, little-endian
                self.assertIn(CPU[arch], subprocess.run(["file", path], capture_output=True, text=True).stdout)
                self.assertEqual(macos.dylibs(path), ["/usr/lib/libSystem.B.dylib"])
                self.assertIn("_PyInit__wiresculpt", objdump("--exports-trie", path))
                headers = objdump("--private-headers", path)
                self.assertRegex(headers, r"LC_BUILD_VERSION[\s\S]*?platform macos[\s\S]*?minos 11\.0")
                if arch == "aarch64":
                    self.assertIn("LC_CODE_SIGNATURE", headers)


if __name__ == "__main__":
    unittest.main()
