"""Authoring tools that sit on top of the runtime (DESIGN: tools on top, never underneath).

- :mod:`authoring.cycles` — motion cycles by performance: one clean loop from several acted ones;
- :mod:`authoring.record_scene` — ``puppetphone author record``: act a layer out, preview, stack;
- :mod:`authoring.mocurves` and :mod:`authoring.edit_scene` — ``puppetphone author edit``.

The runtime never imports this package.
"""

__all__: list[str] = []
