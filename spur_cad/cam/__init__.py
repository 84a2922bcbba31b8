"""CAM layer: tools, machine model, recommendations, 4-axis roughing and finishing generators
(pure functions returning the toolpath IR), and cycle-time estimates. No G-code here."""
