"""engine/store/FORMAT.md's column list is what `kinesweep schema` prints: the section between the
BEGIN/END markers must equal the command's markdown output, so the documentation cannot drift from
the parameter and metric tables.

usage: /usr/bin/python3 check_format_doc.py KINESWEEP_BINARY FORMAT_MD
"""
import difflib
import subprocess
import sys

BEGIN = "<!-- BEGIN kinesweep schema"
END = "<!-- END kinesweep schema -->"


def documented(path):
    lines = open(path, encoding="utf-8").read().split("\n")
    start = next(i for i, l in enumerate(lines) if l.startswith(BEGIN))
    end = next(i for i, l in enumerate(lines) if l.startswith(END))
    return "\n".join(lines[start + 1:end]).strip("\n")


def main():
    exe, doc = sys.argv[1], sys.argv[2]
    generated = subprocess.run([exe, "schema"], capture_output=True, text=True, check=True).stdout.strip("\n")
    written = documented(doc)
    if generated == written:
        print("FORMAT.md column list matches `kinesweep schema`")
        print("1 passed, 0 failed")
        return 0
    sys.stdout.writelines(difflib.unified_diff(written.splitlines(True), generated.splitlines(True),
                                               "FORMAT.md", "kinesweep schema"))
    print("\nFORMAT.md's column list differs from the tables: paste `kinesweep schema` between the markers")
    print("0 passed, 1 failed")
    return 1


if __name__ == "__main__":
    sys.exit(main())
