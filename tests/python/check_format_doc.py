"""engine/store/FORMAT.md's column list is what `kinesweep schema` prints: the section between the
BEGIN/END markers must equal the command's markdown output, so the documentation cannot drift from
the parameter and metric tables.

usage: /usr/bin/python3 check_format_doc.py KINESWEEP_BINARY FORMAT_MD [--write]
(--write replaces the section with the command's output instead of comparing.)
"""
import difflib
import subprocess
import sys

BEGIN = "<!-- BEGIN kinesweep schema"
END = "<!-- END kinesweep schema -->"


def section(path):
    """The file's lines and the indices of the BEGIN and END markers."""
    lines = open(path, encoding="utf-8").read().split("\n")
    start = next(i for i, l in enumerate(lines) if l.startswith(BEGIN))
    end = next(i for i, l in enumerate(lines) if l.startswith(END))
    return lines, start, end


def documented(path):
    lines, start, end = section(path)
    return "\n".join(lines[start + 1:end]).strip("\n")


def main():
    exe, doc = sys.argv[1], sys.argv[2]
    generated = subprocess.run([exe, "schema"], capture_output=True, text=True, check=True).stdout.strip("\n")
    if "--write" in sys.argv[3:]:
        lines, start, end = section(doc)
        with open(doc, "w", encoding="utf-8") as f:
            f.write("\n".join(lines[:start + 1] + generated.split("\n") + lines[end:]))
        print(f"{doc}: column list rewritten from `kinesweep schema`")
        return 0
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
