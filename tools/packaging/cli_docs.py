#!/usr/bin/python3
"""Writes the man pages and bash completions of brdf and brdf-view from their --help texts.

Run by cmake/Packaging.cmake after the tools are linked, so the pages and the completions say
exactly what the built programs say (CLI11's help layout: a description line, "Usage:", then
sections "Positionals:", "Options:", "Subcommands:" or a group name such as "Testing:", with
entries indented by two spaces and descriptions in column 30, and a free-text footer).

Usage: cli_docs.py --brdf BRDF [--brdf-view BRDF_VIEW] --version V --changelog FILE --out DIR
Writes DIR/man/brdf.1.gz, DIR/man/brdf-view.1.gz, DIR/completions/brdf, DIR/completions/brdf-view
and DIR/changelog.gz. The pages are dated by the changelog's newest entry, whose version must be
the project's (a release without its changelog entry fails the build).
"""
import argparse
import email.utils
import gzip
import os
import re
import subprocess
import sys

HEADER = re.compile(r"^([A-Z][A-Za-z ]*):$")
ENTRY = re.compile(r"^  (\S.*?)(?:\s{2,}(\S.*))?$")
CONTINUATION = re.compile(r"^\s{3,}(\S.*)$")


def run_help(program, *args):
    out = subprocess.run([program, *args, "--help"], check=True, capture_output=True, text=True,
                         env=dict(os.environ, COLUMNS="80"))
    return out.stdout


class Help:
    """One --help text: description, usage, sections of (spec, description) and footer."""

    def __init__(self, text, program_name):
        self.description = ""
        self.usage = ""
        self.sections = []  # [(title, [(spec, description)])]
        self.footer = []
        lines = text.splitlines()
        i = 0
        while i < len(lines) and not lines[i].startswith("Usage:"):
            self.description += (" " if self.description else "") + lines[i].strip()
            i += 1
        if i < len(lines):
            # argv[0] as the program was called: the page names the installed command.
            self.usage = re.sub(r"^Usage: \S+", "Usage: " + program_name, lines[i])
            i += 1
        entries = None
        for line in lines[i:]:
            if not line.strip():
                continue
            m = HEADER.match(line)
            if m:
                entries = []
                self.sections.append((m.group(1), entries))
                continue
            if entries is not None and line.startswith("  ") and not line.startswith("   "):
                m = ENTRY.match(line)
                entries.append([m.group(1), m.group(2) or ""])
                continue
            m = CONTINUATION.match(line)
            if entries is not None and entries and m:
                entries[-1][1] += (" " if entries[-1][1] else "") + m.group(1)
                continue
            entries = None
            self.footer.append(line.strip())

    def options(self):
        """(names, takes_value, choices) of every option entry in every section."""
        found = []
        for title, entries in self.sections:
            if title in ("Positionals", "Subcommands"):
                continue
            for spec, _ in entries:
                tokens = spec.split(" ")
                names = tokens[0].split(",")
                rest = " ".join(tokens[1:])
                takes_value = bool(re.match(r"(TEXT|FLOAT|INT|UINT|NUMBER)", rest))
                m = re.search(r"\{([^}]*)\}", rest)
                choices = m.group(1).split(",") if m else []
                found.append((names, takes_value, choices))
        return found

    def subcommands(self):
        for title, entries in self.sections:
            if title == "Subcommands":
                return [(spec, description) for spec, description in entries]
        return []


def roff(text):
    """Escapes plain text for roff: backslashes, hyphens (kept as ASCII minus signs, so options
    can be copied), non-ASCII characters as groff's \\[uXXXX] glyphs. Words too long for an
    80-column terminal (a CSV header, a path) may break after a comma or slash (\\:)."""
    words = []
    for word in text.split(" "):
        if len(word) > 30:
            word = re.sub(r"([,/])(?=.)", "\\1\x00", word)
        words.append(word)
    out = " ".join(words).replace("\\", "\\e").replace("-", "\\-").replace("\x00", "\\:")
    out = "".join(c if ord(c) < 128 else "\\[u%04X]" % ord(c) for c in out)
    return out


def paragraph(text):
    line = roff(text)
    return "\\&" + line if line.startswith((".", "'")) else line


def spec_roff(spec):
    """An entry's spec with its option names (or positional name) in bold."""
    tokens = spec.split(" ")
    names = ", ".join("\\fB%s\\fR" % roff(n) for n in tokens[0].split(","))
    rest = roff(" ".join(tokens[1:]))
    return names + (" " + rest if rest else "")


def help_body(h, heading_macro):
    """The page text of one --help: for a subcommand (heading_macro None) its description,
    usage, entries and footer; for the program (".SH") its sections as page sections."""
    out = []
    if not heading_macro:
        out.append(paragraph(h.description))
        out.append(".PP")
        out.append(paragraph(h.usage))
    for title, entries in h.sections:
        if title == "Subcommands":
            continue
        out.append("%s %s" % (heading_macro, roff(title.upper())) if heading_macro else ".PP")
        if not heading_macro:
            out.append("\\fI%s:\\fR" % roff(title))
        for spec, description in entries:
            out.append(".TP")
            out.append(spec_roff(spec))
            out.append(paragraph(description) if description else "\\&")
    if h.footer:
        out.append(".PP")
        for line in h.footer:
            out.append(paragraph(line))
    return out


FILES = [
    ("/usr/share/brdf-toolchain/materials", "the virtual sample library (the material names "
     "every command accepts), found from the executable's folder as ../share/brdf-toolchain/materials"),
    ("/usr/lib/brdf-toolchain", "modules loaded on first use (libbrdf_oiio_reader.so, which reads "
     "images through OpenImageIO), found from the executable's folder as ../lib/brdf-toolchain"),
    ("/usr/lib/udev/rules.d/70-brdf-scatterometer.rules", "gives the plugdev group and the "
     "logged-in user access to the instrument's USB and HID interfaces"),
]
ENVIRONMENT = [
    ("BRDF_MATERIALS_DIR", "the folder of the material library, instead of the installed one"),
    ("BRDF_MODULE_DIR", "the folder of the modules, instead of the installed one"),
]


def man_page(name, version, date, h, subcommand_helps):
    out = ['.TH %s 1 "%s" "brdf-toolchain %s" "User Commands"' % (roff(name.upper()), date, version)]
    # Left-aligned, no hyphenation: options and paths are shown whole, never stretched.
    out += [".ad l", ".nh"]
    out.append(".SH NAME")
    summary = h.description.split(": ", 1)[-1] if h.description.startswith(name + ":") else h.description
    out.append("%s \\- %s" % (roff(name), roff(summary)))
    out.append(".SH SYNOPSIS")
    usage = h.usage[len("Usage: "):] if h.usage.startswith("Usage: ") else h.usage
    out.append(paragraph(usage))
    out.append(".SH DESCRIPTION")
    if h.subcommands():
        out.append(paragraph("%s COMMAND --help prints the text of each command below." % name))
        for sub, description in h.subcommands():
            out.append(".TP")
            out.append("\\fB%s\\fR" % roff(sub))
            out.append(paragraph(description))
    else:
        out.append(paragraph(h.description.split(": ", 1)[-1]))
    out.extend(help_body(h, ".SH"))
    if subcommand_helps:
        out.append(".SH COMMANDS")
        for sub, sh in subcommand_helps:
            out.append('.SS "%s %s"' % (roff(name), roff(sub)))
            out.extend(help_body(sh, None))
    out.append(".SH ENVIRONMENT")
    for var, what in ENVIRONMENT:
        out.append(".TP")
        out.append("\\fB%s\\fR" % roff(var))
        out.append(paragraph(what))
    out.append(".SH FILES")
    for path, what in FILES:
        if path.endswith(".rules") and name != "brdf":
            continue  # only brdf talks to the instrument
        out.append(".TP")
        out.append("\\fI%s\\fR" % roff(path))
        out.append(paragraph(what))
    out.append(".SH SEE ALSO")
    other = "brdf-view" if name == "brdf" else "brdf"
    out.append("\\fB%s\\fR(1)" % roff(other))
    return "\n".join(out) + "\n"


def shell_words(words):
    for w in words:
        if not re.fullmatch(r"[A-Za-z0-9_.,:+-]+", w):
            sys.exit("cli_docs.py: unexpected character in completion word %r" % w)
    return " ".join(words)


def option_block(options, indent):
    """Sets `opts` to the option names and completes the values of the option before the cursor:
    a fixed set of choices, or file names (bash's default) for any other value."""
    out = ['%sopts="%s"' % (indent, shell_words([n for names, _, _ in options for n in names]))]
    cases = []
    for names, takes_value, choices in options:
        if takes_value and choices:
            cases.append('%s  %s) COMPREPLY=($(compgen -W "%s" -- "$cur")); return ;;'
                         % (indent, "|".join(names), shell_words(choices)))
    valued = [n for names, takes_value, choices in options if takes_value and not choices
              for n in names]
    if valued:
        cases.append("%s  %s) return ;;" % (indent, "|".join(valued)))
    if cases:
        out += ["%scase $prev in" % indent] + cases + ["%sesac" % indent]
    return out


def completion(program, h, subcommand_helps):
    fn = "_" + program.replace("-", "_")
    out = ["# bash completion for %s, generated from its --help (tools/packaging/cli_docs.py)" % program,
           "%s() {" % fn,
           '  local cur="${COMP_WORDS[COMP_CWORD]}" prev="${COMP_WORDS[COMP_CWORD-1]}"',
           "  COMPREPLY=()"]
    top_options = [n for names, _, _ in h.options() for n in names]
    if subcommand_helps:
        commands = [sub for sub, _ in subcommand_helps]
        out.append('  local commands="%s"' % shell_words(commands))
        out.append("  local sub='' i")
        out.append("  for ((i = 1; i < COMP_CWORD; i++)); do")
        out.append('    case " $commands " in *" ${COMP_WORDS[i]} "*) sub=${COMP_WORDS[i]}; break ;; esac')
        out.append("  done")
        out.append('  if [[ -z $sub ]]; then')
        out.append('    if [[ $cur == -* ]]; then')
        out.append('      COMPREPLY=($(compgen -W "%s" -- "$cur"))' % shell_words(top_options))
        out.append("    else")
        out.append('      COMPREPLY=($(compgen -W "$commands" -- "$cur"))')
        out.append("    fi")
        out.append("    return")
        out.append("  fi")
        out.append("  local opts=''")
        out.append('  case $sub in')
        for sub, sh in subcommand_helps:
            out.append("    %s)" % sub)
            out.extend(option_block(sh.options(), "      "))
            out.append("      ;;")
        out.append("  esac")
    else:
        out.append("  local opts")
        out.extend(option_block(h.options(), "  "))
    out.append('  if [[ $cur == -* ]]; then')
    out.append('    COMPREPLY=($(compgen -W "$opts" -- "$cur"))')
    out.append("  fi")
    out.append("}")
    out.append("complete -o default -F %s %s" % (fn, program))
    return "\n".join(out) + "\n"


def write(path, data):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--brdf", required=True)
    ap.add_argument("--brdf-view")
    ap.add_argument("--version", required=True)
    ap.add_argument("--changelog", required=True)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    with open(a.changelog, encoding="utf-8") as f:
        changelog = f.read()
    m = re.match(r"brdf-toolchain \(([^)]*)\)", changelog)
    if not m or m.group(1) != a.version:
        sys.exit("%s: the newest entry is for version %s, expected %s (the project's version): "
                 "add an entry for it" % (a.changelog, m.group(1) if m else "(none)", a.version))
    trailer = re.search(r"^ -- .*?>  (.*)$", changelog, re.M)
    if not trailer:
        sys.exit("%s: the newest entry has no ' -- NAME <EMAIL>  DATE' line" % a.changelog)
    date = email.utils.parsedate_to_datetime(trailer.group(1)).strftime("%Y-%m-%d")
    write(os.path.join(a.out, "changelog.gz"), gzip.compress(changelog.encode("utf-8"), 9, mtime=0))
    programs = [("brdf", a.brdf)] + ([("brdf-view", a.brdf_view)] if a.brdf_view else [])
    for name, exe in programs:
        h = Help(run_help(exe), name)
        subs = [(sub, Help(run_help(exe, sub), name)) for sub, _ in h.subcommands()]
        page = man_page(name, a.version, date, h, subs).encode("utf-8")
        # gzip -9n: maximum compression, no name or time stamp (Debian policy 12.1, reproducible).
        write(os.path.join(a.out, "man", name + ".1.gz"), gzip.compress(page, 9, mtime=0))
        write(os.path.join(a.out, "completions", name), completion(name, h, subs).encode("utf-8"))


if __name__ == "__main__":
    main()
