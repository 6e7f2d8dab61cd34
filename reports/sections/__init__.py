"""The report's sections, one module per kind of scene (:mod:`reports.sections.dynamics` with
:mod:`reports.sections.contact`, :mod:`reports.sections.ik`, :mod:`reports.sections.kinematics`,
:mod:`reports.sections.joint_dynamics`) and per part of the summary (:mod:`reports.sections.summary_tables`,
:mod:`reports.sections.findings`, :mod:`reports.sections.hard_cases`); what they all read is
:mod:`reports.sections.context`, what they say alike :mod:`reports.sections.shared`. :mod:`reports.content` puts them
in order."""
