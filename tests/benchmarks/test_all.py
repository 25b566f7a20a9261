"""`housingfe bench all` page generation from small fake CSVs (no benchmark runs, no timings): tables, pictures,
hand-written notes kept and placed, quick and failed runs never touching docs/."""
import pytest

from housingfe.benchmarks import all as bench_all
from housingfe.errors import SolverError

NOTES = """<!-- comment: the notes file's own explanation -->
Intro written by hand.

<!-- notes: modal -->
Modal analysis: Q3 wins.

<!-- notes: retired -->
Notes of a benchmark that no longer runs.
"""
INFO = {"date (UTC)": "2026-11-23 22:00", "cores": "2", "PETSc": "3.18.5"}


def _fake(tmp_path, name, rows, png=True):
    folder = tmp_path / "results" / name
    folder.mkdir(parents=True)
    (folder / f"{name}.csv").write_text("case,dofs,wall_s,max_err_pct\n" + "".join(rows))
    if png:
        (folder / f"{name}.png").write_bytes(b"\x89PNG fake")
    return folder


def _result(name, folder, exit_code=0):
    return {"name": name, "out": folder, "exit": exit_code, "wall_s": 12.345, "peak_gb": 0.5,
            "load_before": 1.5, "load_after": 2.25, "error": "boom" if exit_code else ""}


def test_page_has_every_table_picture_and_note_in_place(tmp_path):
    modal = _fake(tmp_path, "modal", ["Q2 hex 23.4 mm,38997,10.912345,2.5912345\n", "Q3 hex|40,44256,16.9,1.07\n"])
    frf = _fake(tmp_path, "frf", [f"line{i},1,{i}.5,0\n" for i in range(bench_all.MAX_ROWS + 5)], png=False)
    notes = tmp_path / "notes.md"
    notes.write_text(NOTES)
    page = tmp_path / "docs" / "benchmarks.md"
    bench_all.publish([_result("modal", modal), _result("frf", frf)], INFO, notes, page, tmp_path / "docs" / "img",
                      quick=False)
    text = page.read_text()
    assert "| Q2 hex 23.4 mm | 38997 | 10.91 | 2.591 |" in text          # floats to 4 digits, integers kept
    assert "Q3 hex\\|40" in text                                         # a pipe in a cell does not split it
    assert "… 5 more rows in `frf.csv`" in text and "| line39 |" in text and "| line40 |" not in text
    assert (tmp_path / "docs" / "img" / "modal-modal.png").read_bytes() == b"\x89PNG fake"
    assert "![modal](img/modal-modal.png)" in text
    assert "| PETSc | 3.18.5 |" in text and "Load average (1 min) during the runs: 1.50 – 2.25 on 2 cores" in text
    # notes: intro below the header, each block after its own benchmark's table, a retired one kept
    i_intro, i_modal_table = text.index("Intro written by hand."), text.index("| Q2 hex 23.4 mm")
    i_modal_note, i_frf = text.index("Modal analysis: Q3 wins."), text.index("## housingfe bench frf")
    assert i_intro < i_modal_table < i_modal_note < i_frf
    assert "Notes of a benchmark that no longer runs." in text
    assert "the notes file's own explanation" not in text
    assert not list(page.parent.glob(".*tmp*"))                          # atomic write left no temporary file


def test_quick_and_failed_runs_leave_the_docs_alone(tmp_path, monkeypatch):
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "benchmarks.md").write_text("documented page")
    (docs / "benchmarks-notes.md").write_text(NOTES)
    monkeypatch.setattr(bench_all, "docs_dir", lambda: docs)
    monkeypatch.setattr(bench_all, "benchmarks", lambda: ["modal", "frf"])
    monkeypatch.setattr(bench_all, "machine_info", lambda: dict(INFO))
    fail = set()

    def fake_run(name, out_dir, quick):
        out_dir.mkdir(parents=True, exist_ok=True)
        (out_dir / f"{name}.csv").write_text(f"case,quick\n{name},{quick}\n")
        return _result(name, out_dir, 1 if name in fail else 0)

    monkeypatch.setattr(bench_all, "run_benchmark", fake_run)
    bench_all.main(tmp_path / "out", quick=True)
    assert (docs / "benchmarks.md").read_text() == "documented page"
    quick_page = (tmp_path / "out" / "benchmarks.md").read_text()
    assert "quick mode" in quick_page and "| modal | True |" in quick_page
    fail.add("frf")
    with pytest.raises(SolverError, match="frf"):
        bench_all.main(tmp_path / "out2", quick=False)
    assert (docs / "benchmarks.md").read_text() == "documented page"
    assert "**failed** (exit 1): boom" in (tmp_path / "out2" / "benchmarks.md").read_text()
    fail.clear()
    bench_all.main(tmp_path / "out3", quick=False)
    full = (docs / "benchmarks.md").read_text()
    assert "| modal | False |" in full and "Modal analysis: Q3 wins." in full


def test_bench_all_runs_every_other_benchmark_once():
    names = bench_all.benchmarks()
    # the modal benchmark leads the page (the headline comparison); every command appears exactly once
    assert "all" not in names and names[0] == "modal" and len(set(names)) == len(names)
    assert {"mpi", "frf", "direct"} <= set(names)


def test_only_replaces_its_sections_and_keeps_the_others(tmp_path, monkeypatch):
    """`bench all --only modal` re-runs modal alone: its section gets the new table and says so, frf's section
    and the header stay, the header names the re-run; an unknown name is refused before anything runs."""
    from housingfe.errors import InputError

    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "benchmarks-notes.md").write_text(NOTES)
    modal = _fake(tmp_path, "modal", ["old modal row,1,1.0,9.9\n"])
    frf = _fake(tmp_path, "frf", ["frf row,1,2.0,0\n"], png=False)
    bench_all.publish([_result("modal", modal), _result("frf", frf)], INFO, docs / "benchmarks-notes.md",
                      docs / "benchmarks.md", docs / "img", quick=False)
    monkeypatch.setattr(bench_all, "docs_dir", lambda: docs)
    monkeypatch.setattr(bench_all, "benchmarks", lambda: ["modal", "frf"])
    monkeypatch.setattr(bench_all, "machine_info", lambda: {**INFO, "date (UTC)": "2026-11-25 01:00"})
    ran = []

    def fake_run(name, out_dir, quick):
        ran.append(name)
        out_dir.mkdir(parents=True, exist_ok=True)
        (out_dir / f"{name}.csv").write_text("case,dofs,wall_s,max_err_pct\nnew modal row,2,0.5,0.8\n")
        return _result(name, out_dir)

    monkeypatch.setattr(bench_all, "run_benchmark", fake_run)
    with pytest.raises(InputError, match="unknown benchmark"):
        bench_all.main(tmp_path / "out0", only=["modall"])
    assert ran == []
    bench_all.main(tmp_path / "out", only=["modal"])
    assert ran == ["modal"]
    text = (docs / "benchmarks.md").read_text()
    modal_part = text[text.index("## housingfe bench modal"):text.index("## housingfe bench frf")]
    assert "| new modal row |" in modal_part and "old modal row" not in text
    assert "Re-run alone by `housingfe bench all --only modal` on 2026-11-25 01:00" in modal_part
    assert "Modal analysis: Q3 wins." in modal_part                       # the notes block still follows
    assert "| frf row |" in text[text.index("## housingfe bench frf"):]
    assert "Sections re-run alone since: modal on 2026-11-25 01:00 UTC" in text
    assert "Generated by `housingfe bench all` on 2026-11-23 22:00 UTC" in text   # the full run's header stays
    # a second re-run is added to the header's list; a section re-run again moves to the newest entry
    monkeypatch.setattr(bench_all, "machine_info", lambda: {**INFO, "date (UTC)": "2026-11-25 02:00"})
    bench_all.main(tmp_path / "out2", only=["frf"])
    assert ("Sections re-run alone since: modal on 2026-11-25 01:00 UTC; frf on 2026-11-25 02:00 UTC (`--only`)."
            in (docs / "benchmarks.md").read_text())
    monkeypatch.setattr(bench_all, "machine_info", lambda: {**INFO, "date (UTC)": "2026-11-25 03:00"})
    bench_all.main(tmp_path / "out3", only=["modal"])
    assert ("Sections re-run alone since: frf on 2026-11-25 02:00 UTC; modal on 2026-11-25 03:00 UTC (`--only`)."
            in (docs / "benchmarks.md").read_text())


def test_notes_refresh_replaces_the_hand_written_blocks_only(tmp_path, monkeypatch):
    """`bench all --notes`: edited notes replace their blocks in the page (header, a benchmark's, a retired one's),
    tables and timings stay byte for byte, nothing runs; a page without markers, or notes for a benchmark the page
    does not show, is refused with the reason."""
    docs = tmp_path / "docs"
    docs.mkdir()
    (docs / "benchmarks-notes.md").write_text(NOTES)
    modal = _fake(tmp_path, "modal", ["modal row,1,1.0,0.9\n"])
    bench_all.publish([_result("modal", modal)], INFO, docs / "benchmarks-notes.md", docs / "benchmarks.md",
                      docs / "img", quick=False)
    before = (docs / "benchmarks.md").read_text()
    monkeypatch.setattr(bench_all, "docs_dir", lambda: docs)
    monkeypatch.setattr(bench_all, "run_benchmark", lambda *a: pytest.fail("--notes must not run a benchmark"))
    (docs / "benchmarks-notes.md").write_text(NOTES.replace("Intro written by hand.", "A new intro.")
                                              .replace("Q3 wins.", "S2R wins, 5.3x."))
    bench_all.main(tmp_path / "out", notes_only=True)
    after = (docs / "benchmarks.md").read_text()
    assert "A new intro." in after and "S2R wins, 5.3x." in after and "Q3 wins." not in after
    assert "Notes of a benchmark that no longer runs." in after
    assert after.replace("A new intro.", "Intro written by hand.").replace("S2R wins, 5.3x.", "Q3 wins.") == before
    (docs / "benchmarks-notes.md").write_text(NOTES + "\n<!-- notes: frf -->\nfrf notes\n")
    with pytest.raises(SolverError, match="shows no block for frf"):
        bench_all.main(tmp_path / "out", notes_only=True)
    (docs / "benchmarks.md").write_text("# a page from before the markers\n")
    with pytest.raises(SolverError, match="no marked notes blocks"):
        bench_all.main(tmp_path / "out", notes_only=True)
