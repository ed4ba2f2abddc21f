"""dynamics/integrators"""
