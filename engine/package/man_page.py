#!/usr/bin/env python3
"""Write kinesweep.1, the man page, from the program's own --help texts (CLI11's layout) and the fixed
sections below.

    python3 man_page.py --kinesweep build/kinesweep --out build/kinesweep.1 [--source-dir SRC]

Sections, in man-pages(7) order: NAME, SYNOPSIS, DESCRIPTION, COMMANDS (one subsection per subcommand
with its options, from `kinesweep SUB --help`), OPTIONS (the program's own), EXIT STATUS, ENVIRONMENT,
FILES, EXAMPLES, SEE ALSO. Every paragraph is filled by man, so the page fits any width from 80
columns up; the few unfilled lines (synopsis and examples) are at most 72 characters wide.

Footer: the source field is "kinesweep VERSION (commit SHORT)" from `kinesweep --version`; the date
field is an ISO date: $SOURCE_DATE_EPOCH when set, else the date of the source tree's commit
(--source-dir, a git checkout), else today (UTC).
Standard library only.
"""
import argparse
import datetime
import os
import re
import subprocess
import sys

NAME = "parameter-sweep studies of redundant manipulators"
UNFILLED_WIDTH = 72  # unfilled lines are indented by 7 columns: 79 at most at 80 columns

DESCRIPTION = [
    "kinesweep runs a study, a TOML file that names a robot, a task and blocks of runs, over every "
    "combination of the swept parameters (grids, Latin hypercubes, random draws, Saltelli designs), "
    "in parallel threads (or MPI ranks), and stores every run's parameters, metrics and history in "
    "one HDF5 results file. The file can be resumed after an interruption, read while a sweep writes "
    "it, queried, and analysed by the Python package kinesweep (python3 -m kinesweep lists its "
    "commands).",
    "Results do not depend on the thread count, the rank count, the SIMD lane width or the resume "
    "history: every stored column but wall_time is bitwise identical.",
]

EXIT_STATUS = [
    ("0", "Success."),
    ("1", "A results-file problem: the file is missing, is not a kinesweep results file, is damaged or "
          "unreadable, already exists (run without --resume or --overwrite), cannot be written (or the "
          "disk is full: the file keeps its last commit and --resume completes it), or a resume is "
          "refused because the study, its robot, task or history policy changed."),
    ("2", "Bad input: a malformed study file, robot (URDF) file or argument (reported as "
          "FILE:LINE:COL: error: what was expected); an unknown column, metric or history array; a "
          "malformed --where expression. Nothing is written."),
    ("130", "Interrupted by SIGINT (Ctrl-C) or SIGTERM: kinesweep run commits the runs in flight, "
            "prints the command that resumes the study and exits; a signal before the results file is "
            "opened leaves nothing written."),
]

ENVIRONMENT = [
    ("OMPI_COMM_WORLD_SIZE, PMIX_RANK, PMI_RANK, PMI_SIZE, MPI_LOCALNRANKS",
     "Set by mpirun or srun: kinesweep run then runs as one rank of a distributed sweep (when built "
     "with MPI); each rank writes a shard beside the results file and rank 0 merges them."),
    ("SOURCE_DATE_EPOCH", "Read when the man page is generated (at build time): the date in its footer."),
    ("PYTHONPATH", "Where python3 finds the kinesweep package when it is installed under a prefix that "
                   "python3 does not search (lib/python3.X/dist-packages under the prefix)."),
]

FILES = [
    ("STUDY.toml", "A study file: [study], [robot], [task] and [[block]] tables; the shipped studies and "
                   "their description are in share/kinesweep/studies/ (README.md there)."),
    ("results/NAME.h5", "The results file (HDF5, also .hdf5), by default results/ followed by the "
                        "study's name; its layout is share/doc/kinesweep/FORMAT.md."),
    ("NAME.h5.journal", "The journal of a results file that a sweep is writing: after a crash or kill "
                        "-9, --resume completes the file from its last commit."),
    ("NAME.h5.rankN.h5", "The shard of MPI rank N of a distributed sweep, merged into NAME.h5 at the end."),
    ("share/doc/kinesweep/",
     "README.md (the whole tool), FORMAT.md (the results format), analysis.md (the Python package), "
     "CITATION.cff (how to cite kinesweep), LICENSE."),
    ("share/bash-completion/completions/kinesweep", "Bash completion of subcommands, options and values."),
    ("lib/cmake/kinesweep/", "The CMake package: find_package(kinesweep) and the target kinesweep::engine."),
]

EXAMPLES = [
    ("Run a shipped study on 4 threads, then list its 5 best runs by E:",
     ["kinesweep run share/kinesweep/studies/thesis_table4.toml \\",
      "    -o t4.h5 --threads 4",
      "kinesweep query t4.h5 --sort E -n 5"]),
    ("Estimate a study's runs, size and time without writing anything:",
     ["kinesweep run study.toml --dry-run"]),
    ("Complete a run that was interrupted (Ctrl-C, kill, full disk):",
     ["kinesweep run study.toml -o results.h5 --resume"]),
    ("Summarise a results file, filter its runs, print one run's history:",
     ["kinesweep info results.h5",
      "kinesweep query results.h5 --where 'E<60' --where status=ok \\",
      "    --columns run_id,alpha1A,k,E --format csv",
      "kinesweep query results.h5 --run 3 --history tau,q"]),
    ("The best run of each method:",
     ["kinesweep query results.h5 --group-by method \\",
      "    --agg count,min:E,argmin:E"]),
    ("Sobol' indices of a Saltelli design:",
     ["kinesweep sensitivity results.h5 --metric E --format json"]),
    ("Check a URDF chain and print its joints:",
     ["kinesweep robot arm.urdf --base base_link --tip tool0"]),
    ("The study file's parameters and metrics, as Markdown:",
     ["kinesweep schema --format markdown"]),
    ("Plot and report with the Python package:",
     ["python3 -m kinesweep.plot_landscape results.h5 --log",
      "python3 -m kinesweep.report results.h5 -o report.html"]),
]

SEE_ALSO = [
    "python3 -m kinesweep (the analysis commands: plot_landscape, plot_runs, report, ...), "
    "h5dump(1), ncdump(1), mpirun(1).",
    "share/doc/kinesweep/README.md and FORMAT.md under the installation prefix.",
]


def esc(text):
    """Roff-escaped text: backslashes, hyphens as \\- (minus, so options copy as typed), and a leading
    period or apostrophe guarded."""
    text = text.replace("\\", "\\e").replace("-", "\\-")
    return "\\&" + text if text[:1] in (".", "'") else text


def help_text(kinesweep, *args):
    p = subprocess.run([kinesweep, *args, "--help"], capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"man_page.py: {kinesweep} {' '.join(args)} --help exited {p.returncode}: {p.stderr}")
    # CLI11 names the program by argv[0]
    return p.stdout.replace(kinesweep, "kinesweep")


def parse_help(text):
    """CLI11 (2.x) help: (description lines, usage, {section: [(name, description)]}). An entry starts
    two spaces in; its description follows after two or more spaces or on the next lines, deeper."""
    desc, usage, sections, current = [], "", {}, None
    for line in text.splitlines():
        if line.startswith("Usage: "):
            usage = line[len("Usage: "):].strip()
        elif re.match(r"^[A-Z][A-Za-z ]*:$", line):
            current = sections.setdefault(line[:-1], [])
        elif current is None:
            if line.strip():
                desc.append(line.strip())
        elif re.match(r"^  \S", line):
            m = re.match(r"^  (\S.*?)(?:\s{2,}(.*))?$", line)
            current.append([m.group(1).strip(), (m.group(2) or "").strip()])
        elif line.strip() and current:
            current[-1][1] = (current[-1][1] + " " + line.strip()).strip()
    return desc, usage, sections


def option_head(name):
    """`-w,--where TEXT ...` as bold option names and an italic value."""
    words = name.split(" ", 1)
    flags = ", ".join(f"\\fB{esc(f)}\\fR" for f in words[0].split(","))
    if len(words) > 1:
        flags += " \\fI" + esc(words[1]) + "\\fR"
    return flags


def entries(items):
    out = []
    for name, desc in items:
        out += [".TP", option_head(name), esc(desc) if desc else ""]
    return [line for line in out if line != ""]


def unfilled(lines):
    for line in lines:
        if len(line) > UNFILLED_WIDTH:
            sys.exit(f"man_page.py: an unfilled line is wider than {UNFILLED_WIDTH} characters: {line}")
    return [".PP", ".nf", ".RS 4"] + [esc(line) for line in lines] + [".RE", ".fi"]


def page_date(source_dir):
    if os.environ.get("SOURCE_DATE_EPOCH"):
        when = datetime.datetime.fromtimestamp(int(os.environ["SOURCE_DATE_EPOCH"]), datetime.timezone.utc)
        return when.strftime("%Y-%m-%d")
    if source_dir:
        p = subprocess.run(["git", "-C", source_dir, "log", "-1", "--format=%cd", "--date=format:%Y-%m-%d"],
                           capture_output=True, text=True)
        if p.returncode == 0 and re.fullmatch(r"\d{4}-\d\d-\d\d", p.stdout.strip()):
            return p.stdout.strip()
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d")


def page_source(kinesweep):
    """'kinesweep 0.1.0 (commit abc1234)' from `kinesweep --version` ('kinesweep 0.1.0 (<git describe>)');
    'abc1234+' for a build of a modified tree (git's -dirty: the short form keeps the footer's three
    fields apart at 80 columns)."""
    p = subprocess.run([kinesweep, "--version"], capture_output=True, text=True)
    m = re.match(r"kinesweep (\S+)(?: \((.*)\))?", p.stdout.strip())
    if p.returncode != 0 or not m:
        sys.exit(f"man_page.py: {kinesweep} --version printed {p.stdout!r}")
    version, describe = m.group(1), m.group(2) or ""
    sha = re.search(r"(?:^|-g)([0-9a-f]{7,40})(?:-dirty)?$", describe)
    if not sha:
        return f"kinesweep {version}"
    return f"kinesweep {version} (commit {sha.group(1)[:7]}{'+' if describe.endswith('-dirty') else ''})"


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--kinesweep", required=True, help="the kinesweep program")
    p.add_argument("--out", required=True, help="the man page to write")
    p.add_argument("--source-dir", help="the source tree (its commit's date is the page's date)")
    a = p.parse_args()
    ks = os.path.abspath(a.kinesweep)
    _, _, top = parse_help(help_text(ks))
    subcommands = top.get("Subcommands", [])
    if not subcommands:
        sys.exit("man_page.py: `kinesweep --help` lists no subcommands")

    out = [f'.TH KINESWEEP 1 "{page_date(a.source_dir)}" "{page_source(ks)}" "User Commands"',
           ".nh", ".ad l", ".SH NAME", f"kinesweep \\- {esc(NAME)}", ".SH SYNOPSIS"]
    for name, _ in subcommands:
        _, usage, _ = parse_help(help_text(ks, name))
        words = usage.split()
        out += ([] if out[-1] == ".SH SYNOPSIS" else [".br"]) + [
                f"\\fBkinesweep\\fR \\fB{esc(name)}\\fR " + esc(" ".join(words[2:]))]
    out += [".br", "\\fBkinesweep\\fR [\\fB\\-\\-help\\fR | \\fB\\-\\-version\\fR]"]
    out += [".SH DESCRIPTION"]
    for i, para in enumerate(DESCRIPTION):
        out += ([".PP"] if i else []) + [esc(para)]

    out += [".SH COMMANDS", "Each command's options follow its name; \\fBkinesweep \\fICOMMAND\\fB \\-\\-help\\fR "
            "prints them."]
    for name, summary in subcommands:
        desc, usage, sections = parse_help(help_text(ks, name))
        out += [f".SS kinesweep {esc(name)}", esc(summary if summary else " ".join(desc))]
        if desc and " ".join(desc) != summary:
            out += [".PP", esc(" ".join(desc))]
        out += [".PP", f"\\fBUsage:\\fR {esc(usage)}"]
        for section in ("Positionals", "Options"):
            if sections.get(section):
                out += [".PP", f"{section}:", ".RS 4"] + entries(sections[section]) + [".RE"]
    out += [".SH OPTIONS"] + entries(top.get("Options", []))
    out += [".SH EXIT STATUS"]
    for code, text in EXIT_STATUS:
        out += [".TP", f"\\fB{code}\\fR", esc(text)]
    out += [".SH ENVIRONMENT"]
    for var, text in ENVIRONMENT:
        out += [".TP", ", ".join(f"\\fB{esc(v.strip())}\\fR" for v in var.split(",")), esc(text)]
    out += [".SH FILES", "Paths under share/ and lib/ are under the installation prefix."]
    for path, text in FILES:
        out += [".TP", f"\\fI{esc(path)}\\fR", esc(text)]
    out += [".SH EXAMPLES"]
    for i, (text, lines) in enumerate(EXAMPLES):
        out += ([".PP"] if i else []) + [esc(text)] + unfilled(lines)
    out += [".SH SEE ALSO"]
    for i, para in enumerate(SEE_ALSO):
        out += ([".PP"] if i else []) + [esc(para)]
    with open(a.out, "w") as f:
        f.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
