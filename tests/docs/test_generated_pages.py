"""The generated result pages take the pipeline's files when they exist, and say so when they do not."""

import shutil

from docs_paths import ROOT, vemkit_docs


def test_verification_page_uses_the_pipeline_file_when_present(tmp_path, monkeypatch):
    from vemkit.studies.verification import run_case, verification_dataset, write_verification

    records = run_case("cook", ROOT / "config" / "scenes" / "cook.yaml", "square", sizes=[4.0])
    made = tmp_path / "results" / "verification"
    (made / "figures").mkdir(parents=True)
    write_verification(verification_dataset(records), made / "verification.nc")
    shutil.copy(ROOT / "docs" / "_static" / "paper-deformed.png", made / "figures" / "cook.png")
    monkeypatch.setattr(vemkit_docs, "ROOT", tmp_path)
    text = vemkit_docs.verification_tables(tmp_path / "out")
    assert "Generated from the pipeline's `results/verification/verification.nc`" in text
    assert "v(48, 52)" in text and "absent" not in text
    assert "![cook](/_generated/verification/cook.png)" in text and (tmp_path / "out" / "cook.png").exists()
    assert not any(line.startswith("# ") for line in text.splitlines())  # under the page's own title


def test_absent_result_files_are_named(tmp_path, monkeypatch):
    monkeypatch.setattr(vemkit_docs, "ROOT", tmp_path)
    path, origin = vemkit_docs.result_file("table1.nc")
    assert path is None and "absent" in origin
    assert "absent" in vemkit_docs.paper_tables() and "make reproduce" in vemkit_docs.paper_tables()
    assert "absent" in vemkit_docs.adaptivity_summary()


def test_paper_tables_come_from_the_archive_without_the_pipeline():
    if (ROOT / "results" / "table1.nc").exists():
        return  # the pipeline's own file wins; covered by the built site
    text = vemkit_docs.paper_tables()
    assert "the committed archive `results/archive/table1.nc`" in text
    assert "| paper | Table 1 | error | 1.9114e-01 |" in text
