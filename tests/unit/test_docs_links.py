"""The shipped docs resolve: links, mentioned paths and section citations (issue 16, "docs that ship").

* every relative markdown link ``[..](path)`` / ``![..](path)`` in docs/*.md, README.md and the markdown files
  under examples/ points at a file or folder of the repository, and its ``#anchor`` (if any) at a heading of the
  target (GitHub-style slug) or an explicit ``<a id=..>`` / ``<a name=..>``;
* every ``docs/….md`` and ``examples/…`` path mentioned in those files exists (globs: at least one match);
* every citation "METHOD §x.y", "method.md §x.y", "VALIDATION §x", "validation.md §x" (also "§a–b" ranges and
  "§a, §b" lists) and "VALIDATION T1.2" anywhere in docs/, examples/, src/ and tests/ names a section that
  docs/method.md / docs/validation.md has;
* the user-facing markdown cites docs/method.md and docs/validation.md, not the design notes that live outside
  the repository (METHOD.md, VALIDATION.md, CRACK_GAS.md, ARCHITECTURE.md, ../shared/design).
"""

from __future__ import annotations

import re
import unicodedata
from functools import lru_cache
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
METHOD = ROOT / "docs" / "method.md"
VALIDATION = ROOT / "docs" / "validation.md"


def user_markdown() -> list[Path]:
    files = sorted((ROOT / "docs").glob("*.md")) + [ROOT / "README.md"]
    files += sorted(p for p in (ROOT / "examples").rglob("*.md") if "__pycache__" not in p.parts)
    return files


def cited_sources() -> list[Path]:
    out = []
    for top in ("docs", "examples", "src", "tests"):
        for p in sorted((ROOT / top).rglob("*")):
            if p.is_file() and p.suffix in (".md", ".py", ".toml", ".txt") and "__pycache__" not in p.parts:
                out.append(p)
    return out + [ROOT / "README.md"]


def rel(p: Path) -> str:
    return str(p.relative_to(ROOT))


# ----------------------------------------------------------------------------- headings and anchors
FENCE = re.compile(r"^(```|~~~)")


def strip_code_blocks(text: str) -> str:
    """The text with fenced code blocks blanked (line count kept): links and headings there are not markdown."""
    out, fenced = [], False
    for line in text.splitlines():
        if FENCE.match(line.strip()):
            fenced = not fenced
            out.append("")
            continue
        out.append("" if fenced else line)
    return "\n".join(out)


def github_slug(heading: str) -> str:
    """GitHub's anchor for a heading: markdown stripped, lower case, punctuation dropped, spaces → '-'."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)        # links and images → their text
    text = re.sub(r"<[^>]+>", "", text)                               # inline HTML
    text = text.strip().lower()
    kept = []
    for ch in text:
        if ch in " -_" or unicodedata.category(ch)[0] in "LN":
            kept.append(ch)
    return "".join(kept).replace(" ", "-")


@lru_cache(maxsize=None)
def anchors(path: Path) -> frozenset[str]:
    text = strip_code_blocks(path.read_text())
    seen: dict[str, int] = {}
    out = set()
    for m in re.finditer(r"^#{1,6}\s+(.*?)\s*#*\s*$", text, re.M):
        slug = github_slug(m.group(1))
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        out.add(slug if n == 0 else f"{slug}-{n}")
    out |= set(re.findall(r"<a\s+(?:id|name)=\"([^\"]+)\"", text))
    return frozenset(out)


@lru_cache(maxsize=None)
def sections(path: Path) -> frozenset[str]:
    """Section numbers ("1", "1.5", "0.2") and test labels ("T1.2") of the headings of a doc page."""
    text = strip_code_blocks(path.read_text())
    out = set()
    for m in re.finditer(r"^#{1,6}\s+(.*)$", text, re.M):
        head = m.group(1).strip()
        num = re.match(r"§?\s*(\d+(?:\.\d+)*)\.?(?:\s|$)", head)
        if num:
            out.add(num.group(1))
        lab = re.match(r"(T\d+(?:\.\d+)*)\b", head)
        if lab:
            out.add(lab.group(1))
    return frozenset(out)


def test_slug_rules():
    assert github_slug("1.2 Interface springs and their stiffness") == "12-interface-springs-and-their-stiffness"
    assert github_slug("0. Two findings about the paper's inputs") == "0-two-findings-about-the-papers-inputs"
    assert (github_slug("Gas in cracks (`[crack_gas]`, coupling/crack_gas.py)")
            == "gas-in-cracks-crack_gas-couplingcrack_gaspy")
    assert github_slug("Velocity transfer: FLIP, PIC or APIC") == "velocity-transfer-flip-pic-or-apic"


def test_the_two_pages_exist_with_the_design_numbering():
    """The numbering the code cites: the CDEM, MPM, coupling, fracture-degree and calibration sections."""
    m = sections(METHOD)
    for s in ["1", *(f"1.{i}" for i in range(1, 10)), "2", *(f"2.{i}" for i in range(1, 8)), "3", "3.1", "3.6",
              "3.7", "4", "5", *(f"5.{i}" for i in range(1, 6)), "6"]:
        assert s in m, f"docs/method.md has no section {s}"
    v = sections(VALIDATION)
    for s in ["0", "0.1", "0.2", "1", "2", "3", "4", "5", "T1.1", "T1.2", "T1.3", "T1.4"]:
        assert s in v, f"docs/validation.md has no section {s}"


# ----------------------------------------------------------------------------- links
LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")


def link_targets(path: Path) -> list[str]:
    text = strip_code_blocks(path.read_text())
    text = re.sub(r"`[^`\n]*`", "", text)                  # inline code is not a link
    return LINK.findall(text)


def check_link(src: Path, target: str) -> str | None:
    if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):      # http:, https:, mailto: ...
        return None
    path_part, _, anchor = target.partition("#")
    dest = src if not path_part else (src.parent / path_part).resolve()
    if not dest.exists():
        return f"{rel(src)}: link to {target}: no such file"
    try:
        dest.relative_to(ROOT)
    except ValueError:
        return f"{rel(src)}: link to {target} leaves the repository"
    if anchor:
        if dest.suffix != ".md":
            return f"{rel(src)}: link to {target}: an anchor into a non-markdown file"
        if anchor not in anchors(dest):
            return f"{rel(src)}: link to {target}: {rel(dest)} has no heading with anchor #{anchor}"
    return None


@pytest.mark.parametrize("doc", user_markdown(), ids=rel)
def test_relative_links_resolve(doc):
    errors = [e for t in link_targets(doc) if (e := check_link(doc, t))]
    assert not errors, "\n".join(errors)


# ----------------------------------------------------------------------------- mentioned paths
PATH_MENTION = re.compile(r"(?<![\w/.\-])((?:docs/[\w.\-/]*?\.md)|(?:examples/[\w.\-/*]+))")


def mentioned_paths(path: Path) -> list[str]:
    out = []
    for m in PATH_MENTION.finditer(path.read_text()):
        p = m.group(1).rstrip(".,;:)")
        if "<" in p:                                     # placeholders such as examples/<name>/
            continue
        out.append(p)
    return out


def path_exists(p: str) -> bool:
    if any(c in p for c in "*?["):
        return any(ROOT.glob(p))
    return (ROOT / p).exists()


@pytest.mark.parametrize("doc", user_markdown(), ids=rel)
def test_mentioned_paths_exist(doc):
    missing = sorted({p for p in mentioned_paths(doc) if not path_exists(p)})
    assert not missing, f"{rel(doc)} mentions paths that do not exist: {missing}"


# ----------------------------------------------------------------------------- section citations
SEC = r"(?:§\s*\d+(?:\.\d+)*(?:\s*[–-]\s*\d+(?:\.\d+)*)?)"
ITEM = r"(?:%s|T\d+\.\d+)" % SEC
CITE = re.compile(r"\b(METHOD|VALIDATION|method|validation)(?:\.md)?\s+(%s(?:(?:\s*,\s*|\s+and\s+)%s)*)" % (ITEM, ITEM))


def expand(numbers: str) -> list[str]:
    """'§1.4–1.5, §3' → ['1.4', '1.5', '3']; 'T1.2' → ['T1.2']."""
    out = []
    for tok in re.findall(r"§\s*\d+(?:\.\d+)*(?:\s*[–-]\s*\d+(?:\.\d+)*)?|T\d+\.\d+", numbers):
        if tok.startswith("T"):
            out.append(tok)
            continue
        parts = [p.strip() for p in re.split(r"[–-]", tok.lstrip("§").strip())]
        out += parts
    return out


def citations(path: Path) -> list[tuple[int, str, str]]:
    """(line, doc 'method'|'validation', section) of every citation in a file."""
    out = []
    for lineno, line in enumerate(path.read_text().splitlines(), 1):
        for m in CITE.finditer(line):
            doc = m.group(1).lower()
            for s in expand(m.group(2)):
                out.append((lineno, doc, s))
    return out


def test_citation_parser():
    def secs(s):
        return [(d, x) for _, d, x in citations_of_text(s)]

    assert secs("(METHOD §1.4–1.5)") == [("method", "1.4"), ("method", "1.5")]
    assert secs("METHOD.md §2.3, §2.6, §2.7") == [("method", "2.3"), ("method", "2.6"), ("method", "2.7")]
    assert secs("VALIDATION T1.2: 5-10 %") == [("validation", "T1.2")]
    assert secs("see docs/validation.md §0.2 and §4") == [("validation", "0.2"), ("validation", "4")]
    assert secs("[method.md §1.5](method.md#15-contact-between-separated-blocks)") == [("method", "1.5")]
    assert secs("VALIDATION.md warns") == []


def citations_of_text(text: str):
    out = []
    for m in CITE.finditer(text):
        out += [(0, m.group(1).lower(), s) for s in expand(m.group(2))]
    return out


def test_every_section_citation_exists():
    known = {"method": sections(METHOD), "validation": sections(VALIDATION)}
    bad = []
    for f in cited_sources():
        for line, doc, s in citations(f):
            if s not in known[doc]:
                bad.append(f"{rel(f)}:{line}: {doc} §{s}")
    assert not bad, "citations of sections that docs/method.md / docs/validation.md lack:\n" + "\n".join(bad)


# ----------------------------------------------------------------------------- no design notes in shipped docs
DESIGN = re.compile(r"\b(?:METHOD|VALIDATION|CRACK_GAS|ARCHITECTURE)(?:\.md)?\s*(?:§|T\d)|"
                    r"\b(?:METHOD|VALIDATION|CRACK_GAS|ARCHITECTURE)\.md\b|shared/design")


@pytest.mark.parametrize("doc", user_markdown() + sorted((ROOT / "examples").rglob("*.toml")), ids=rel)
def test_shipped_docs_cite_the_shipped_pages(doc):
    hits = [f"{rel(doc)}:{n}: {line.strip()[:100]}" for n, line in enumerate(doc.read_text().splitlines(), 1)
            if DESIGN.search(line)]
    assert not hits, "cite docs/method.md or docs/validation.md instead of the design notes:\n" + "\n".join(hits)
