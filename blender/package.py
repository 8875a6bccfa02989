"""Builds the add-on's zip: installs in Blender 3.4+ (Preferences > Add-ons > Install) and in
4.2+ as an extension (Get Extensions > Install from Disk). The zip holds one folder,
formation_flock/, with the manifest, the add-on, the bundled example and, when given, the
command line (--cli) and the Python package's wheel (--wheel).

    python3 blender/package.py -o formation_flock.zip --cli target/release/formation \
        [--wheel target/wheels/formation-0.1.0-cp310-abi3-manylinux_2_34_x86_64.whl]
"""

import argparse
import os
import platform
import stat
import sys
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
ADDON = os.path.join(HERE, "formation_flock")
# A fixed time for every entry: the same inputs give the same zip.
STAMP = (2026, 1, 1, 0, 0, 0)


def platform_tag() -> str:
    machine = {"x86_64": "x64", "AMD64": "x64", "aarch64": "arm64", "arm64": "arm64"}.get(platform.machine(), "x64")
    system = {"Linux": "linux", "Darwin": "macos", "Windows": "windows"}.get(platform.system(), "linux")
    return f"{system}-{machine}"


def add(z: zipfile.ZipFile, arcname: str, data: bytes, executable: bool = False) -> None:
    info = zipfile.ZipInfo(arcname, STAMP)
    info.compress_type = zipfile.ZIP_DEFLATED
    mode = 0o755 if executable else 0o644
    info.external_attr = (stat.S_IFREG | mode) << 16
    z.writestr(info, data)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--out", required=True, help="the zip to write")
    ap.add_argument("--cli", help="the formation program to bundle (bin/formation)")
    ap.add_argument("--wheel", help="the formation wheel to bundle (wheels/)")
    a = ap.parse_args()

    manifest = open(os.path.join(ADDON, "blender_manifest.toml")).read()
    extra = []
    if a.cli or a.wheel:
        extra.append(f'platforms = ["{platform_tag()}"]')
    if a.wheel:
        extra.append(f'wheels = ["./wheels/{os.path.basename(a.wheel)}"]')
    if extra:
        marker = "# package.py adds"
        head, _, tail = manifest.partition(marker)
        tail = tail.split("\n", 1)[1]
        manifest = head + "\n".join(extra) + "\n" + tail

    tmp = a.out + ".part"
    with zipfile.ZipFile(tmp, "w") as z:
        for name in sorted(os.listdir(ADDON)):
            if name.endswith(".py"):
                add(z, f"formation_flock/{name}", open(os.path.join(ADDON, name), "rb").read())
        add(z, "formation_flock/blender_manifest.toml", manifest.encode())
        example = os.path.join(ROOT, "examples_data", "barnacle_geese_v.json")
        add(z, "formation_flock/examples/barnacle_geese_v.json", open(example, "rb").read())
        for lic in ("LICENSE-MIT", "LICENSE-APACHE"):
            add(z, f"formation_flock/{lic}", open(os.path.join(ROOT, lic), "rb").read())
        if a.cli:
            add(z, "formation_flock/bin/formation", open(a.cli, "rb").read(), executable=True)
        if a.wheel:
            add(z, f"formation_flock/wheels/{os.path.basename(a.wheel)}", open(a.wheel, "rb").read())
    os.replace(tmp, a.out)
    print(f"{a.out}: {os.path.getsize(a.out) / 1e6:.1f} MB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
