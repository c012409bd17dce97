"""Helpers every kind of benchmark uses: rendering a drawing to pixels (`render`), processes
and their CPU time (`processes`), a regular install and the start-up ratio (`user_install`,
`startup_ratio`), and running another checkout's code (`checkout`)."""
