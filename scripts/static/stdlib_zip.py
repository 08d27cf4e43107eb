"""Builds the standard-library zip embedded in static nesy binaries.

Run with the same CPython minor version the binary links (Debian's python3.11). A fresh
isolated interpreter imports what nesy's embedded runtime imports at start-up (the
`encodings` package and `ast` with its dependencies); every pure-Python module
it loaded is compiled to .pyc with this interpreter and written into an uncompressed
(STORED) zip, because zipimport would need zlib to read deflated entries. Modules frozen
into or built into libpython are not needed and skipped.

usage: python3.11 -I -S stdlib_zip.py OUT.zip
"""
import importlib.util
import marshal
import os
import subprocess
import sys
import zipfile

PROBE = """
import sys, os, encodings
import ast
stdlib = os.path.dirname(os.__file__)
names = {n for n, m in list(sys.modules.items())
         if (getattr(m, '__file__', None) or '').endswith('.py') and m.__file__.startswith(stdlib + os.sep)}
import pkgutil
names.update('encodings.' + i.name for i in pkgutil.iter_modules(encodings.__path__))
print('\\n'.join(sorted(names)))
"""


def runtime_modules():
    out = subprocess.run([sys.executable, "-I", "-S", "-c", PROBE], check=True, capture_output=True, text=True)
    return out.stdout.split()


def pyc_bytes(source, code):
    # Unchecked hash-based pyc (flags = 0b01): there is no source file to validate against.
    flags = (1).to_bytes(4, "little")
    return importlib.util.MAGIC_NUMBER + flags + importlib.util.source_hash(source) + marshal.dumps(code)


def main(out):
    stdlib = os.path.dirname(os.__file__)
    entries = []
    for name in runtime_modules():
        origin = importlib.util.find_spec(name).origin
        if not origin or not os.path.isfile(origin):
            continue  # frozen into libpython
        relative = os.path.relpath(origin, stdlib)
        with open(origin, "rb") as f:
            source = f.read()
        code = compile(source, relative, "exec", dont_inherit=True)
        entries.append((relative[:-3] + ".pyc", pyc_bytes(source, code)))
    with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_STORED) as z:
        for arcname, data in sorted(entries):
            info = zipfile.ZipInfo(arcname, date_time=(2020, 1, 1, 0, 0, 0))
            z.writestr(info, data, compress_type=zipfile.ZIP_STORED)
    total = sum(len(d) for _, d in entries)
    print(f"{out}: {len(entries)} modules, {total / 1e6:.2f} MB of bytecode", file=sys.stderr)


if __name__ == "__main__":
    main(sys.argv[1])
