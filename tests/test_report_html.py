"""The HTML report a reader can navigate (issue 20, item 4): rendered by headless Chromium, every image loads
and every link resolves; every page leads back to the contents; the answer pages are HTML text.

Chromium is a system package (README, "How to read the report": ``apt-get install chromium``). Without it the
browser test is skipped with that command (``make test`` passes on a machine with only Python and make), and fails
where the browser is required: CI (``.ci/run`` installs Chromium and sets ``ROCKFRAG_BROWSER=required``)."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess

import pytest

BROWSER_REQUIRED = "ROCKFRAG_BROWSER"
"""``ROCKFRAG_BROWSER=required``: a missing Chromium fails the browser test instead of skipping it (.ci/run)."""

BROWSERS = ("chromium", "chromium-browser", "google-chrome", "chromium-headless-shell")
INSTALL = "apt-get install chromium"

CHECK = """<script>window.addEventListener('load', () => {
  const images = [...document.images];
  const bad = images.filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.alt.slice(0, 80));
  const links = [...document.querySelectorAll('a[href]')].map(a => a.getAttribute('href'));
  const broken = links.filter(h => !(h.startsWith('#') && document.getElementById(h.slice(1))));
  const out = document.createElement('pre');
  out.id = 'rockfrag-check';
  out.textContent = JSON.stringify({images: images.length, bad, links: links.length, broken});
  document.body.appendChild(out);
});</script>"""
"""Appended to a copy of report.html: the browser's own verdict on every image and link, after loading."""


def chromium() -> str:
    """The Chromium executable; skip (or fail where it is required) with the install command when missing."""
    for name in BROWSERS:
        found = shutil.which(name)
        if found:
            return found
    reason = f"headless Chromium is not installed: {INSTALL} (as root, after apt-get update); see the README"
    if os.environ.get(BROWSER_REQUIRED) == "required":
        pytest.fail(reason)
    pytest.skip(reason)


def test_every_image_loads_and_every_link_resolves_in_chromium(small_pipeline, tmp_path):
    """~3 s: one headless Chromium load of the small study's report."""
    browser = chromium()
    html = (small_pipeline.output / "report.html").read_text()
    page = tmp_path / "report.html"
    page.write_text(html.replace("</body>", CHECK + "</body>"))
    done = subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--virtual-time-budget=20000",
                           "--dump-dom", page.as_uri()], capture_output=True, text=True, timeout=120)
    found = re.search(r"<pre id=\"rockfrag-check\">(.*?)</pre>", done.stdout)
    assert found, f"Chromium did not run the check (exit {done.returncode}): {done.stderr[-500:]}"
    result = json.loads(found.group(1))
    figures = html.count("<img ")
    assert result["images"] == figures > 0 and result["bad"] == []
    assert result["links"] > 0 and result["broken"] == []


def test_every_page_leads_back_to_the_contents_and_sections_have_anchors(small_pipeline):
    html = (small_pipeline.output / "report.html").read_text()
    sections = re.findall(r"<section id='page-(\d+)'>(.*?)</section>", html, flags=re.S)
    contents = next(number for number, body in sections if "<h2>Contents</h2>" in body)
    back = f"<a href='#page-{contents}'>Back to the contents</a>"
    assert all(back in body for number, body in sections if number != contents)
    for section in ("Summary", "Answers", "Methods", "Limitations", "Glossary", "References",
                    "How to reproduce this report"):
        slug = "section-" + re.sub(r"[^a-z0-9]+", "-", section.lower())
        assert f"id='{slug}'" in html and f"href='#{slug}'" in html, section
    front = [body for number, body in sections if 1 < int(number) < int(contents)]  # the summary, as text
    assert front and all("<img" not in body and "<table>" in body for body in front)
    assert int(contents) == len(front) + 2  # the title, the summary, then the contents


def test_a_missing_chromium_fails_where_required_and_skips_elsewhere_with_the_install_command(monkeypatch):
    monkeypatch.setattr(shutil, "which", lambda name: None)
    monkeypatch.setenv(BROWSER_REQUIRED, "required")
    with pytest.raises(pytest.fail.Exception, match=INSTALL):
        chromium()
    monkeypatch.delenv(BROWSER_REQUIRED)
    with pytest.raises(pytest.skip.Exception, match=INSTALL):
        chromium()


def test_each_section_link_lands_on_its_own_heading_without_the_pdfs_page_count():
    """Issue 20: Methods -> "Summary (3/3)": a section starting part-way down a page was anchored before the page,
    on the previous section's heading; headings copied the PDF's "(2/9)" and "page N of M"."""
    from rockfrag.report import _packed_pages, contents_page, html_document
    from rockfrag.report.text import paragraph

    long = [paragraph(f"line {n} " + "word " * 20) for n in range(90)]  # over two pages
    short = [paragraph("a few lines") for _ in range(3)]
    parts = [("alpha", "Alpha", "Alpha section", long), ("beta", "Beta", "Beta section", short),
             ("gamma", "Gamma", "Gamma section", short)]
    pages = _packed_pages(parts)
    assert len(pages) >= 2 and any(page.also for page in pages)  # beta starts part-way down a page
    document = html_document("t", [contents_page(pages, "t", position=1), *pages])
    for _, section, title, _ in parts:
        at = document.index(f"id='section-{section.lower()}'")
        following = re.search(r"<h[23][^>]*>(.*?)</h[23]>", document[at - 4:])
        assert following and following.group(1) == title, (section, following and following.group(1))
    assert "page 1 of" not in document and "(1/" not in document and "part-way" not in document
    assert document.count("<h2>Alpha section</h2>") == 1
