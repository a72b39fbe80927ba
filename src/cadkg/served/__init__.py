"""What a transport serves: the cell a target names (:mod:`.target`) and the served graph
with its session, swapped for a rebuilt one while requests run (:mod:`.holder`)."""
