"""The pythonfmu slaves: the contact model (rotorub_casing_contact.py) and the LP spool (spool_slave.py).

Each file is a pythonfmu script that the build stages under a hashed module name; importing them from
here is only for reading their defaults and interfaces.
"""
