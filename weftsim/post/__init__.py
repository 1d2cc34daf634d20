"""Results, output and plots: what a run leaves behind.

:mod:`weftsim.post.results` is the result of one run (:class:`~weftsim.post.results.RunResult`),
:mod:`weftsim.post.result_file` and :mod:`weftsim.post.npz_guard` read a saved one as untrusted input,
:mod:`weftsim.post.analysis` takes its peaks, statistics and energy balance and :mod:`weftsim.post.compare`
sets the two engines side by side; :mod:`weftsim.post.output`, :mod:`weftsim.post.record` and
:mod:`weftsim.post.provenance` write results to disk with what made them; :mod:`weftsim.post.plots`,
:mod:`weftsim.post.animate` and :mod:`weftsim.post.display` draw them.
"""
