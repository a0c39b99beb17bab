"""Pure music data: notes, pieces, MIDI and PIG files, phrases, the score tensor, the task families and the metrics that compare a performance with its score. No physics, no torch."""
