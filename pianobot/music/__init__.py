"""Pure music data: notes, pieces, MIDI and PIG files, phrases and the score tensor. No physics, no torch."""
