marker(-1, { media = image "../../../etc/passwd" })
marker(0/0, {})
dictionary "NOPE"
