"""The planning core: tasks, who does each and why, precedence, and their order (docs/plan.md).

It knows no use case: each use case turns its files into a :class:`~cadkg.plan.tasks.Problem`
(``UseCase.planner``), and :func:`~cadkg.plan.order.make_plan` orders it.
"""
