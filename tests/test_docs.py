"""The documentation cannot rot: the user guide builds strictly (every link, anchor and API
reference resolves, the API pages come from the docstrings), a broken anchor fails that
build, the README stays a front door and every file it links exists."""
import os
import re
import shutil
import subprocess
import sys

from conftest import ROOT


def mkdocs(config, site):
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    return subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict",
                           "-f", str(config), "-d", str(site)],
                          capture_output=True, text=True, cwd=config.parent, env=env)


def test_user_guide_builds_strictly_with_api_pages(tmp_path):
    done = mkdocs(ROOT / "mkdocs.yml", tmp_path / "site")
    assert done.returncode == 0, done.stdout + done.stderr
    api = (tmp_path / "site" / "api" / "index.html").read_text()
    # the API page carries the docstrings, not just the names
    assert "Read and validate a scene file" in api and "hydrofmu.cosim.result.Result" in api


def test_a_broken_anchor_fails_the_strict_build(tmp_path):
    """The guide's own settings (strict, link and anchor validation), without the API pages
    (the build above has them) to keep it short."""
    import yaml
    shutil.copytree(ROOT / "docs", tmp_path / "docs", ignore=shutil.ignore_patterns("api.md", "img"))
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text())
    config["plugins"] = ["search"]
    config["nav"] = [page for page in config["nav"] if "api.md" not in page.values()]
    config["theme"] = {"name": "mkdocs"}
    (tmp_path / "mkdocs.yml").write_text(yaml.safe_dump(config))
    for page in (tmp_path / "docs").glob("*.md"):   # the pictures are not copied
        page.write_text(page.read_text().replace("![", "["))
    page = tmp_path / "docs" / "tuning.md"
    page.write_text(page.read_text() + "\nSee [nowhere](conventions.md#no-such-section).\n")
    done = mkdocs(tmp_path / "mkdocs.yml", tmp_path / "site")
    assert done.returncode != 0 and "no-such-section" in done.stdout + done.stderr


def test_readme_is_a_front_door_whose_links_exist():
    text = (ROOT / "README.md").read_text()
    assert len(text.splitlines()) <= 250
    links = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", text)
    assert links, "the README points to the guide"
    for link in links:
        if "://" not in link:
            assert (ROOT / link).exists(), link
    # every guide page the nav lists is linked from the README or the guide's home page
    nav = re.findall(r":\s*([\w-]+\.md)\s*$", (ROOT / "mkdocs.yml").read_text(), re.M)
    home = (ROOT / "docs" / "index.md").read_text()
    for page in nav:
        assert page == "index.md" or page in home, page


def test_the_waves_page_opens_with_the_buoy_scene_as_it_is():
    """docs/waves.md opens with a complete scene: models/buoy_in_waves.toml, word for word
    (the demo runs it; a changed scene changes the page)."""
    page = (ROOT / "docs" / "waves.md").read_text()
    first = page.split("```toml\n", 1)[1].split("```", 1)[0]
    assert page.index("```toml") < page.index("\n## Waves (first order)")
    assert first == (ROOT / "models" / "buoy_in_waves.toml").read_text()
