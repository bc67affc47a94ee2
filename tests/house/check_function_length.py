#!/usr/bin/env python3
"""The house rule on long functions (docs/architecture.md, Conventions).

A function body of more than LIMIT lines in src/ or python/src must say why it
is one piece: a comment containing "one piece" within the three lines above
its signature or in its first three lines. Lists every offender and exits 1;
with --list, prints every function over the limit (with or without a reason)
and exits 0.

The parser is a brace matcher over the source with comments, strings and
character literals blanked: a function body is a '{' whose preceding code ends
in ')' (possibly followed by const, noexcept, override, final, mutable or a
trailing return type) and does not belong to a control statement, a lambda,
or an initialiser. Bodies nested in a function count towards that function.
"""
import pathlib
import re
import sys

LIMIT = 80
ROOT = pathlib.Path(__file__).resolve().parents[2]
DIRS = ["src", "python/src"]
CONTROL = {"if", "for", "while", "switch", "catch", "return", "sizeof", "decltype"}


def blank(text):
    """Comments, strings and char literals replaced by spaces; newlines kept."""
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
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
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


def opens_function(code, pos):
    """True when the '{' at pos opens a function body."""
    head = code[max(0, pos - 400):pos].rstrip()
    head = re.sub(r"(\s*(const|noexcept|override|final|mutable))+$", "", head)
    head = re.sub(r"\s*->\s*[\w:<>,\s&*]+$", "", head)
    if not head.endswith(")"):
        return False
    depth, k = 0, len(head) - 1
    while k >= 0:
        depth += {")": 1, "(": -1}.get(head[k], 0)
        if depth == 0:
            break
        k -= 1
    before = head[:k].rstrip()
    if before.endswith("]") or before.endswith(">"):  # a lambda, or a template call
        return before.endswith(">") and re.search(r"\w\s*<[^<>]*>$", before) is not None
    name = re.search(r"([\w:~]+)$", before)
    return name is not None and name.group(1) not in CONTROL


def long_functions(path):
    text = path.read_text()
    code = blank(text)
    lines = text.splitlines()
    found, stack = [], []
    for m in re.finditer(r"[{}]", code):
        if m.group() == "{":
            is_fn = not any(s[1] for s in stack) and opens_function(code, m.start())
            stack.append((m.start(), is_fn))
        elif stack:
            start, is_fn = stack.pop()
            if is_fn:
                first = code.count("\n", 0, start)
                last = code.count("\n", 0, m.start())
                if last - first - 1 > LIMIT:
                    found.append((first, last - first - 1))
    for first, length in found:
        window = "\n".join(lines[max(0, first - 4):first + 4])
        yield first + 1, length, "one piece" in window


def self_test(tmp):
    """The checker finds a seeded long function and accepts one that says why."""
    body = "".join(f"  x += {i};\n" for i in range(LIMIT + 1))
    path = pathlib.Path(tmp) / "seeded.cpp"
    path.write_text(f"int f(int x) {{\n{body}  return x;\n}}\n"
                    f"// one piece: seeded\nint g(int x) const {{\n{body}  return x;\n}}\n"
                    "int h() { return 1; }\n")
    got = [(line, reason) for line, _, reason in long_functions(path)]
    assert got == [(1, False), (LIMIT + 6, True)], got
    print("check_function_length: seeded functions found as expected")


def main():
    if "--self-test" in sys.argv:
        import tempfile
        with tempfile.TemporaryDirectory() as tmp:
            self_test(tmp)
    listing = "--list" in sys.argv
    bad = 0
    for d in DIRS:
        for path in sorted((ROOT / d).rglob("*.[ch]pp")):
            for line, length, reason in long_functions(path):
                rel = path.relative_to(ROOT)
                if listing or not reason:
                    tag = "(says why)" if reason else "OVER THE LIMIT, no reason given"
                    print(f"{rel}:{line}: {length} lines {tag}")
                bad += not reason
    if bad and not listing:
        print(f"{bad} function(s) over {LIMIT} lines without a comment saying why "
              "they are one piece (docs/architecture.md)")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
