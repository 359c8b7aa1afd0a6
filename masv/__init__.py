"""MASV: modal multi-engine layer (four engines, eight actuators, thrust-structure modes).

masv imports taos; taos never imports masv.
"""
