"""The stress mode's parts: bounded busy processes, pass counts from JUnit XML."""

import pytest

from subapf_planner.tools.stress import MAX_PER_CORE, Busy, cores, tally

pytestmark = pytest.mark.core


def test_busy_processes_run_until_stopped_and_are_bounded():
    with Busy(1, max_seconds=30) as busy:
        assert len(busy.procs) == cores()
        assert all(p.poll() is None for p in busy.procs)
        procs = list(busy.procs)
    assert all(p.poll() is not None for p in procs)
    with Busy(1, max_seconds=0.2) as busy:   # they end on their own, too
        for p in busy.procs:
            assert p.wait(10) == 0
    with pytest.raises(ValueError):
        Busy(MAX_PER_CORE + 1)


def test_pass_counts_from_junit_xml(tmp_path):
    runs = []
    for k, outcome in enumerate(('', '<failure message="x"/>', '<skipped/>')):
        runs.append(tmp_path / f'run{k}.xml')
        runs[-1].write_text(
            '<testsuites><testsuite name="pytest">'
            '<testcase classname="test.test_a" name="test_x[SIGINT]"/>'
            f'<testcase classname="test.test_a" name="test_y">{outcome}</testcase>'
            '</testsuite></testsuites>')
    passed, ran = tally(runs + [tmp_path / 'missing.xml'])
    assert ran == {'test/test_a.py::test_x[SIGINT]': 3, 'test/test_a.py::test_y': 2}
    assert passed == {'test/test_a.py::test_x[SIGINT]': 3, 'test/test_a.py::test_y': 1}
