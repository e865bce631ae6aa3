"""The papers' studies and the demo, as functions returning tables and figures' data."""
