"""Tokens: 32 random bytes, URL-safe; stored as their SHA-256 (a token is
as strong as a random key, so a salted slow hash adds nothing); compared
in constant time."""
import hashlib
import hmac
import secrets


def new_token():
    return secrets.token_urlsafe(32)


def token_hash(token):
    return hashlib.sha256(token.encode("utf-8", "surrogatepass")).hexdigest()


def same_hash(a, b):
    return hmac.compare_digest(a.encode(), b.encode())
