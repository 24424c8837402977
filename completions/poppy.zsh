
#compdef poppy

_poppy_completion() {
  eval $(env _TYPER_COMPLETE_ARGS="${words[1,$CURRENT]}" _POPPY_COMPLETE=complete_zsh poppy)
}

compdef _poppy_completion poppy

