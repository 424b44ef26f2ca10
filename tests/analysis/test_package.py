"""The analysis package: every re-exported name resolves, and loading results or writing a summary
does not import the plotting stack."""

import subprocess
import sys

import neurocur.analysis as analysis


def test_every_name_in_all_resolves_once():
    names = analysis.__all__
    assert len(names) == len(set(names))
    missing = [n for n in names if getattr(analysis, n, None) is None]
    assert not missing
    assert {"write_all", "fig_efficiency", "two_lines", "write_summary"} <= set(names)
    assert analysis.figures.__name__ == "neurocur.analysis.figures"


def test_importing_analysis_does_not_import_matplotlib():
    code = ("import sys, neurocur.analysis as a; "
            "print(sorted(m for m in ('matplotlib', 'seaborn', 'statsmodels.api') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"


def test_deferred_names_are_the_deferred_modules_all():
    for sub in analysis._DEFERRED:
        module = getattr(analysis, sub)
        assert {n for n, owner in analysis._deferred_names().items() if owner == sub} == set(module.__all__)


def test_dir_and_an_unknown_name_do_not_import_matplotlib():
    code = ("import sys, neurocur.analysis as a; names = dir(a); missing = hasattr(a, 'no_such_name'); "
            "print('write_all' in names, missing, "
            "sorted(m for m in ('matplotlib', 'seaborn', 'statsmodels.api') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "True False []"


def test_no_import_circle_in_the_analysis():
    """No module of the analysis imports, through others, itself; imports inside functions count
    (grimp reads every import statement)."""
    import grimp
    import networkx as nx

    graph = grimp.build_graph("neurocur")
    edges = nx.DiGraph([(m, n) for m in graph.modules if m.startswith("neurocur.analysis")
                        for n in graph.find_modules_directly_imported_by(m) if n.startswith("neurocur.analysis")])
    assert list(nx.simple_cycles(edges)) == []
    assert ("neurocur.analysis.figures.sets", "neurocur.analysis.figures.icub") not in edges.edges  # sets know no world
