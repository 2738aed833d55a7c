#!/usr/bin/env python3
"""Lists the functions longer than a limit in native/ and addon/ (C++ and Python).

Prints `path:line name length` for each function over the limit (default 120 lines, counted from
the line that names the function to the line that closes it) and exits 1 if there is any, so the
test suite keeps the code at none. Python is read with `ast`; C++ with a brace scanner that first
blanks comments, string, character and raw-string literals and preprocessor lines, then finds
function bodies (free functions, methods, constructors, operators and lambdas at namespace or
class scope). No third-party dependencies.

    python3 scripts/long_functions.py [--limit N] [PATH ...]
"""
import argparse
import ast
import bisect
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_PATHS = ("native", "addon")
CPP_SUFFIXES = (".cpp", ".hpp", ".cc", ".h", ".hh", ".cxx", ".hxx", ".inl")


# ---------------------------------------------------------------- Python

def python_functions(source, filename="<string>"):
    """(line, name, length) of every def in `source`, methods and nested defs included."""
    tree = ast.parse(source, filename)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            found.append((node.lineno, node.name, node.end_lineno - node.lineno + 1))
    return sorted(found)


# ---------------------------------------------------------------- C++ lexing

_RAW_PREFIX = re.compile(r'(?:u8|[uUL])?R"([^()\\\s]{0,16})\(')


def _blank(text, start, end):
    """`text[start:end]` with every character but newlines turned into a space."""
    return re.sub(r"[^\n]", " ", text[start:end])


def strip_cpp(source):
    """`source` with comments, literals and preprocessor lines blanked, newlines kept.

    Line numbers and brace structure of the code are preserved; a `{` inside a string, comment,
    character literal, raw string or `#define` no longer counts.
    """
    out = []
    i, n = 0, len(source)
    line_start = True  # only whitespace seen since the last newline
    while i < n:
        c = source[i]
        if c == "\n":
            out.append(c)
            i += 1
            line_start = True
            continue
        if line_start and c == "#":  # preprocessor line, with its backslash continuations
            j = i
            while j < n and source[j] != "\n":
                if source[j] == "\\" and j + 1 < n and source[j + 1] == "\n":
                    j += 2
                    continue
                j += 1
            out.append(_blank(source, i, j))
            i = j
            continue
        if not c.isspace():
            line_start = False
        if source.startswith("//", i):
            j = source.find("\n", i)
            j = n if j < 0 else j
            out.append(_blank(source, i, j))
            i = j
            continue
        if source.startswith("/*", i):
            j = source.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(_blank(source, i, j))
            i = j
            continue
        raw = _RAW_PREFIX.match(source, i) if c in "uULR" else None
        if raw and (i == 0 or not (source[i - 1].isalnum() or source[i - 1] == "_")):
            close = ")" + raw.group(1) + '"'
            j = source.find(close, raw.end())
            j = n if j < 0 else j + len(close)
            out.append(_blank(source, i, j))
            i = j
            continue
        if c == '"' or (c == "'" and not _is_digit_separator(source, i)):
            j = i + 1
            while j < n and source[j] != c and source[j] != "\n":
                j += 2 if source[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(_blank(source, i, j))
            i = j
            continue
        out.append(c)
        i += 1
    return "".join(out)


def _is_digit_separator(source, i):
    """True when the quote at `i` separates digits (1'000'000) rather than opening a char literal."""
    j = i
    while j > 0 and (source[j - 1].isalnum() or source[j - 1] in "_'."):
        j -= 1
    return j < i and source[j].isdigit()


# ---------------------------------------------------------------- C++ functions

_SCOPE_HEAD = re.compile(r"^(?:template\s*<.*>\s*)?(?:namespace\b|extern\s*$|(?:class|struct|union)\b)",
                         re.S)
_ENUM_HEAD = re.compile(r"^(?:typedef\s+)?enum\b")
_CONTROL = re.compile(r"^(?:if|for|while|switch|catch|do|else|try|return)\b")
_TRAILING = re.compile(r"(?:\s*(?:const|noexcept(?:\s*\([^()]*\))?|override|final|mutable|volatile|"
                       r"constexpr|&&|&|->\s*[\w:<>,\s*&]+))*\s*$")
_NAME = re.compile(r"((?:[A-Za-z_]\w*(?:\s*<[^<>]*>)?\s*::\s*)*"
                   r"(?:operator\s*(?:\(\s*\)|[^\s(]+)|~?[A-Za-z_]\w*))\s*$")
_LAMBDA = re.compile(r"\[[^\[\]]*\]\s*(?:\([^()]*(?:\([^()]*\)[^()]*)*\))?" + _TRAILING.pattern)


def _top_level_paren(head):
    """Index of the first '(' at angle/paren depth 0 in `head` that follows a name, or -1."""
    depth = 0
    for k, ch in enumerate(head):
        if ch == "(":
            if depth == 0:
                before = head[:k].rstrip()
                if before.endswith("operator"):
                    depth += 1  # operator() — its parameters come in the next '('
                    continue
                if _NAME.search(before):
                    return k
            depth += 1
        elif ch == ")":
            depth -= 1
    return -1


def _matching_paren(head, k):
    depth = 0
    for j in range(k, len(head)):
        if head[j] == "(":
            depth += 1
        elif head[j] == ")":
            depth -= 1
            if depth == 0:
                return j
    return -1


def _classify(head):
    """What a '{' opens, from the text `head` before it: ('function', name), ('scope', None),
    ('init', None) for a brace initialiser inside a constructor's member list, or ('other', None)."""
    h = " ".join(head.split())
    if not h:
        return "other", None
    if _ENUM_HEAD.match(h):
        return "other", None
    if _SCOPE_HEAD.match(h) and "(" not in h.split("{")[0].split(":")[0]:
        return "scope", None
    if _CONTROL.match(h):
        return "other", None
    lam = _LAMBDA.search(h)
    if lam and "=" in h[:lam.start()]:
        name = _NAME.search(h[:h.rindex("=", 0, lam.start())].rstrip())
        return "function", (name.group(1) if name else "<lambda>")
    if "=" in re.sub(r"operator\s*[=!<>+\-*/%^&|]*=|\([^()]*\)", "", h.split("(")[0]):
        return "other", None  # an initialiser: int a[] = {...}
    k = _top_level_paren(h)
    if k < 0:
        return "other", None
    close = _matching_paren(h, k)
    if close < 0:
        return "other", None
    rest = h[close + 1:]
    name = _NAME.search(h[:k].rstrip()).group(1)
    name = re.sub(r"\s+", "", name)
    if h[:k].rstrip().endswith("operator ( )") or h[:k].rstrip().endswith("operator()"):
        name = name if name.endswith("()") else name + "()"
    if _TRAILING.fullmatch(rest):
        return "function", name
    if re.match(r"\s*(?:(?:const|noexcept|override|final)\s*)*:(?!:)", rest):
        # constructor with a member initialiser list; the '{' ends it unless a member is
        # brace-initialised (`x_{a}`), i.e. a name stands right before the brace
        if re.search(r"[\w>]\s*$", rest) and not re.search(r"\)\s*$", rest):
            return "init", name
        return "function", name
    return "other", None


def cpp_functions(source):
    """(line, name, length) of every function body in C++ `source`.

    Functions nested in a function (local lambdas, local classes) count towards the enclosing
    function and are not listed on their own.
    """
    code = strip_cpp(source)
    found = []
    stack = []  # kinds of the open braces: scope, function, init, other
    head_start = 0
    function_depth = None  # index into stack of the open function body, or None
    line_of = _line_index(code)
    for i, ch in enumerate(code):
        if ch == ";" and function_depth is None and (not stack or stack[-1] == "scope"):
            head_start = i + 1
        elif ch == "{":
            if function_depth is not None or (stack and stack[-1] == "other"):
                stack.append("other")
                continue
            head = code[head_start:i]
            kind, name = _classify(head)
            if kind == "init":
                stack.append("init")
                continue
            stack.append(kind)
            if kind == "function":
                function_depth = len(stack) - 1
                first = head_start + len(head) - len(head.lstrip())
                start_line = line_of(first + _name_offset(head.lstrip(), name))
                found.append([start_line, name, None])
            head_start = i + 1
        elif ch == "}":
            if not stack:
                continue
            kind = stack.pop()
            if kind == "init":
                continue
            if function_depth is not None and len(stack) == function_depth:
                found[-1][2] = line_of(i) - found[-1][0] + 1
                function_depth = None
            if function_depth is None:
                head_start = i + 1
    return sorted((line, name, length) for line, name, length in found if length is not None)


def _name_offset(head, name):
    """Offset of the function's name in `head` (its line is the function's first line)."""
    short = re.split(r"::|\(", name)[-1] if not name.startswith("operator") else "operator"
    short = re.sub(r"[^\w~]", "", name.split("::")[-1]) or short
    m = re.search(r"\b" + re.escape(short.lstrip("~")), head)
    return max(m.start() - (1 if short.startswith("~") else 0), 0) if m else 0


def _line_index(text):
    starts = [0] + [k + 1 for k, ch in enumerate(text) if ch == "\n"]

    def line_of(offset):
        return bisect.bisect_right(starts, offset)
    return line_of


# ---------------------------------------------------------------- driver

def scan_file(path):
    with open(path, encoding="utf-8") as f:
        source = f.read()
    if path.endswith(".py"):
        return python_functions(source, path)
    return cpp_functions(source)


def source_files(paths):
    for top in paths:
        if os.path.isfile(top):
            yield top
            continue
        for dirpath, dirnames, filenames in os.walk(top):
            dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and d != "__pycache__")
            for name in sorted(filenames):
                if name.endswith(".py") or name.endswith(CPP_SUFFIXES):
                    yield os.path.join(dirpath, name)


def long_functions(paths, limit):
    """(path, line, name, length) of every function longer than `limit` lines under `paths`."""
    over = []
    for path in source_files(paths):
        for line, name, length in scan_file(path):
            if length > limit:
                over.append((path, line, name, length))
    return over


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("paths", nargs="*", help="files or folders (default: native/ and addon/)")
    parser.add_argument("--limit", type=int, default=120, help="longest allowed function, in lines")
    parser.add_argument("--all", action="store_true", help="list every function with its length")
    args = parser.parse_args(argv)
    paths = args.paths or [os.path.join(ROOT, p) for p in DEFAULT_PATHS]
    if args.all:
        for path in source_files(paths):
            for line, name, length in scan_file(path):
                print(f"{os.path.relpath(path, ROOT)}:{line} {name} {length}")
        return 0
    over = long_functions(paths, args.limit)
    for path, line, name, length in sorted(over, key=lambda r: -r[3]):
        print(f"{os.path.relpath(path, ROOT)}:{line} {name} {length}")
    return 1 if over else 0


if __name__ == "__main__":
    sys.exit(main())
