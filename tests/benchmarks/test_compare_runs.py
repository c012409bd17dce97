"""`benchmarks.compare_runs`: the no-regression check over two `vectorize_bench --csv` files."""

import csv

from benchmarks import compare_runs, vectorize_bench


def _bench_csv(tmp_path):
    path = tmp_path / "base.csv"
    vectorize_bench.TASKS.clear()
    try:
        assert vectorize_bench.main(["--ground-truth-as-output", "--set", "plain", "--count", "2",
                                     "--classifier", "geometric", "--csv", str(path)]) == 0
    finally:
        vectorize_bench.TASKS.clear()
    return path


def test_a_run_against_itself_and_against_a_lost_drawing(tmp_path, capsys):
    base = _bench_csv(tmp_path)
    assert compare_runs.main([str(base), str(base)]) == 0
    out = capsys.readouterr().out
    assert "plain/geometric" in out and "2 -> 2" in out and "outputs whose length changed: 0 of 2" in out

    # The same rows with the first drawing turned wrong and longer: the set is lower.
    with open(base, newline="") as handle:
        rows = list(csv.DictReader(handle))
    rows[0]["correct"], rows[0]["out_length"] = "False", str(float(rows[0]["out_length"]) + 50.0)
    new = tmp_path / "new.csv"
    with open(new, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    assert compare_runs.main([str(base), str(new)]) == 1
    out = capsys.readouterr().out
    assert f"plain/geometric/{rows[0]['name']}: correct True -> False" in out
    assert "2 -> 1" in out and "outputs whose length changed: 1 of 2" in out and "lower than before: plain/geometric" in out


def test_files_that_cannot_be_compared_are_refused_with_a_message(tmp_path, capsys):
    base = _bench_csv(tmp_path)
    other = tmp_path / "other.csv"
    other.write_text("set,classifier,name,correct,within,out_length,order,strokes\nhershey,cnn,x,True,True,1,1,1\n")
    assert compare_runs.main([str(base), str(other)]) == 2
    assert "no drawing in common" in capsys.readouterr().err
    assert compare_runs.main([str(base), str(tmp_path / "missing.csv")]) == 2
    assert "cannot read" in capsys.readouterr().err
