#!/usr/bin/env python3
"""Checks the project's size rules for C++ sources (issue 15, docs/style.md):
no source file over MAX_FILE lines, no function body over MAX_FUNCTION lines.

  tools/lint/check_sizes.py [--root DIR] [--max-file N] [--max-function N]

Function bodies are found from the text: a '{' that follows a parameter list
')' (optionally followed by const/override/noexcept/final/mutable or a
trailing return type, or a constructor's initialiser list) outside any other
function, and not the body of if/for/while/switch/catch. A function's length
is the number of lines from its '{' to its closing '}'. Comments and string
literals are ignored. Exit 0 when every file keeps the rules, else 1 with one
line per breach "FILE:LINE: ...". Generated code (build folders) is not read.
"""
import argparse
import os
import re
import sys

SOURCE_DIRS = ("common", "services", "tools", "tests")
EXTENSIONS = (".cc", ".h", ".cpp", ".hpp", ".inc")
CONTROL = re.compile(r"\b(if|for|while|switch|catch|return|sizeof|decltype|alignas|static_assert)\s*$")
QUALIFIERS = re.compile(r"\)\s*(?:const|override|noexcept|final|mutable|&|&&|\s)*(?:->\s*[\w:<>,\s*&]+)?$")


def strip_comments_and_strings(text):
    """Replaces comments and string/char literals with spaces, keeping newlines."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = ")" + (m.group(1) if m else "") + '"'
            j = text.find(end, i)
            j = n if j < 0 else j + len(end)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (j + 1 - i))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def is_function_body(prefix):
    """True when the code before a '{' ends a function signature."""
    tail = prefix[-400:].rstrip()
    if not tail.endswith(")") and not QUALIFIERS.search(tail):
        return False
    # Find the '(' matching the last ')' and look at the word before it.
    close = tail.rfind(")")
    depth = 0
    for k in range(close, -1, -1):
        if tail[k] == ")":
            depth += 1
        elif tail[k] == "(":
            depth -= 1
            if depth == 0:
                return not CONTROL.search(tail[:k])
    return False


def function_lengths(text):
    code = strip_comments_and_strings(text)
    stack = []  # (is_function, line of '{')
    in_function = 0
    line = 1
    results = []
    for i, c in enumerate(code):
        if c == "\n":
            line += 1
        elif c == "{":
            fn = in_function == 0 and is_function_body(code[:i])
            stack.append((fn, line))
            in_function += 1 if fn else 0
        elif c == "}" and stack:
            fn, start = stack.pop()
            if fn:
                in_function -= 1
                results.append((start, line - start + 1))
    return results


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", default=os.path.join(os.path.dirname(__file__), "..", ".."))
    ap.add_argument("--max-file", type=int, default=600)
    ap.add_argument("--max-function", type=int, default=80)
    args = ap.parse_args()
    root = os.path.abspath(args.root)
    breaches = []
    files = 0
    for top in SOURCE_DIRS:
        for dirpath, dirnames, filenames in os.walk(os.path.join(root, top)):
            dirnames[:] = [d for d in dirnames if d not in ("build", "node_modules") and not d.startswith(".")]
            for name in sorted(filenames):
                if not name.endswith(EXTENSIONS):
                    continue
                path = os.path.join(dirpath, name)
                rel = os.path.relpath(path, root)
                with open(path, encoding="utf-8", errors="replace") as f:
                    text = f.read()
                files += 1
                lines = text.count("\n")
                if lines > args.max_file:
                    breaches.append(f"{rel}:1: {lines} lines (at most {args.max_file})")
                for start, length in function_lengths(text):
                    if length > args.max_function:
                        breaches.append(f"{rel}:{start}: function of {length} lines (at most {args.max_function})")
    for b in breaches:
        print(b)
    print(f"check_sizes: {files} files, {len(breaches)} breaches", file=sys.stderr)
    return 1 if breaches else 0


if __name__ == "__main__":
    sys.exit(main())
